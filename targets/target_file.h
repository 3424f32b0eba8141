// The target file: a target's layout as plain YAML (docs/formats.md,
// "Target file"). Lossless round trip, like the rig file.
#pragma once

#include <string>

#include "targets/target.h"

namespace stereorig {

// The most inner corners a target file gives along a row or a column
// (corners_x, corners_y), and `stereorig target --corners` takes. A camera
// sees the board whole in its views: 200 squares across the default rig's
// 752 px imager leave under 4 px a square (20 px across a 4000 px one).
// A file's corners_x of 100000 drew a 64 MB SVG; the corner count (an int)
// overflows past 46340 x 46340.
constexpr int kMaxInnerCorners = 200;

// Throws InputError naming the file and key on any problem (unknown or
// missing keys, wrong types, overlapping tags, shared tag IDs, ...).
Target ReadTargetFile(const std::string& path);
Target ParseTargetYaml(const std::string& text, const std::string& where);
std::string TargetToYaml(const Target& target);
void WriteTargetFile(const Target& target, const std::string& path);  // atomic

}  // namespace stereorig
