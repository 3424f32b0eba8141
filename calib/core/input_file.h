// An input file, checked before it is opened: a user who gives a folder
// where a file belongs reads that, not "no such file".
#pragma once

#include <string>

namespace stereorig {

// Throws InputError naming `path` unless it is a regular file (or a link to
// one): "no such file", "is a folder, not a file", or why it cannot be
// looked at (a folder on the way the process may not search).
// With `pipe_too`, a pipe is taken as well (a text input read once from
// start to end, e.g. a YAML file given as `--options <(...)` or
// /dev/stdin); images, which are read by seeking, are not.
void RequireInputFile(const std::string& path, bool pipe_too = false);

// The whole text of a file (or pipe) read once from start to end, after
// RequireInputFile(path, /*pipe_too=*/true). Throws InputError naming it if
// it cannot be read.
std::string ReadInputText(const std::string& path);

}  // namespace stereorig
