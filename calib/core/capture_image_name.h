// The one rule for a capture image's file name: "camK.png", K the camera's
// index in decimal digits without leading zeros (cam0.png, cam12.png; the
// name every reader opens, CameraImageName). check and reconstruct refuse a
// capture holding an image of a camera beyond the rig's; calibrate and check
// protect every such image from their outputs.
#pragma once

#include <optional>
#include <string>

namespace stereorig {

// Beyond any rig: the index returned for a K of more than 6 digits (which
// std::stoi could not even hold).
constexpr int kCameraIndexBeyondAnyRig = 1000000;

// K if `file_name` (a name, not a path) is "camK.png" with K one or more
// decimal digits, no leading zero; kCameraIndexBeyondAnyRig if K has more
// than 6 digits; nullopt for any other name ("cam.png", "cam0.PNG",
// "cam-1.png", "xcam0.png", "cam07.png").
std::optional<int> CameraIndexOfImageName(const std::string& file_name);

// "camK.png".
std::string CameraImageName(int camera);

}  // namespace stereorig
