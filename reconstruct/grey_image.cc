#include "reconstruct/grey_image.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "calib/core/input_error.h"
#include "calib/core/png_file.h"

namespace stereorig {

cv::Mat ReadGreyImage(const std::string& path) {
  // Missing: imread would print OpenCV's own warning first.
  if (!std::filesystem::is_regular_file(path)) throw InputError(path, "no such file");
  CheckPngIsWhole(path);
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {  // e.g. a header whose size the decoder refuses
    throw InputError(path, "cannot read the image (" + e.msg + ")");
  }
  if (image.empty()) throw InputError(path, "cannot read the image (not an image, or a damaged one)");
  if (image.type() != CV_8UC1) throw InputError(path, "must be an 8-bit single-channel (grey) image");
  return image;
}

}  // namespace stereorig
