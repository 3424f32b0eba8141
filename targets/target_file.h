// The target file: a target's layout as plain YAML (docs/formats.md,
// "Target file"). Lossless round trip, like the rig file.
#pragma once

#include <string>

#include "targets/target.h"

namespace stereorig {

// Throws InputError naming the file and key on any problem (unknown or
// missing keys, wrong types, overlapping tags, shared tag IDs, ...).
Target ReadTargetFile(const std::string& path);
Target ParseTargetYaml(const std::string& text, const std::string& where);
std::string TargetToYaml(const Target& target);
void WriteTargetFile(const Target& target, const std::string& path);  // atomic

}  // namespace stereorig
