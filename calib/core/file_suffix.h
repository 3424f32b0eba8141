// Output formats chosen by a path's suffix, read as users write them:
// "cloud.PLY" names a PLY file as much as "cloud.ply" does.
#pragma once

#include <string_view>

namespace stereorig {

// Whether `path` ends in `suffix` (e.g. ".ply"), ASCII letters compared
// without case.
bool EndsWithIgnoringCase(std::string_view path, std::string_view suffix);

}  // namespace stereorig
