// The layout file: which cameras form each stereo module (docs/formats.md).
//
//   modules:
//     - {name: module0, left: 0, right: 1}               # module 0 is the reference
//     - {name: module1, left: 2, right: 3, face: back}   # face: optional, front|back
//
// `face`, if given, is the only face of the target that module can see; a
// detection of the other face is then refused as "face seen by the wrong
// module". Strict: unknown keys and bad values are InputErrors naming the key.
#pragma once

#include <string>
#include <vector>

#include "calib/observations.h"

namespace stereorig {

std::vector<ModuleLayout> ReadLayoutFile(const std::string& path);
std::vector<ModuleLayout> ParseLayoutYaml(const std::string& text, const std::string& where);

// The number of cameras a layout names: one more than its highest camera
// index (cameras 0 .. N-1, each camK.png of a capture).
int LayoutCameraCount(const std::vector<ModuleLayout>& modules);

}  // namespace stereorig
