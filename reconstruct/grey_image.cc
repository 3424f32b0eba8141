#include "reconstruct/grey_image.h"

#include "calib/core/input_error.h"
#include "reconstruct/image_file.h"

namespace stereorig {

cv::Mat ReadGreyImage(const std::string& path) {
  cv::Mat image = ReadImageFile(path);
  if (image.type() != CV_8UC1) throw InputError(path, "must be an 8-bit single-channel (grey) image");
  return image;
}

}  // namespace stereorig
