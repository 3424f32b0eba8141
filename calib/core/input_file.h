// An input file, checked before it is opened: a user who gives a folder
// where a file belongs reads that, not "no such file".
#pragma once

#include <string>

namespace stereorig {

// Throws InputError naming `path` unless it is a regular file (or a link to
// one): "no such file", or "is a folder, not a file".
void RequireInputFile(const std::string& path);

}  // namespace stereorig
