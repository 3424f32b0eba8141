#include "calib/core/capture_image_name.h"

#include <algorithm>
#include <cctype>

namespace stereorig {

std::optional<int> CameraIndexOfImageName(const std::string& file_name) {
  const std::string prefix = "cam", suffix = ".png";
  if (file_name.size() <= prefix.size() + suffix.size() || file_name.compare(0, prefix.size(), prefix) != 0 ||
      file_name.compare(file_name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  const std::string digits = file_name.substr(prefix.size(), file_name.size() - prefix.size() - suffix.size());
  if (!std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c) != 0; }))
    return std::nullopt;
  if (digits.size() > 1 && digits[0] == '0') return std::nullopt;  // cam07.png: not a name any reader opens
  if (digits.size() > 6) return kCameraIndexBeyondAnyRig;
  return std::stoi(digits);
}

std::string CameraImageName(int camera) { return "cam" + std::to_string(camera) + ".png"; }

}  // namespace stereorig
