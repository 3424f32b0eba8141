#include "reconstruct/grey_image.h"

#include "calib/core/input_error.h"
#include "reconstruct/image_file.h"

namespace stereorig {

cv::Mat ReadGreyImage(const std::string& path) {
  int bits = 0;  // as stored: the decoder scales 1-, 2- and 4-bit grey to 8 bits
  cv::Mat image = ReadImageFile(path, &bits);
  if (image.type() != CV_8UC1) throw InputError(path, "must be an 8-bit single-channel (grey) image");
  // A 1-, 2- or 4-bit grey image holds 2-16 grey levels: the sub-pixel fit
  // and the lit test read steps, not the laser lines' profile (a 1-bit
  // capture gave 0 points, a 4-bit one silently fewer). Refused, as
  // docs/formats.md says: 8-bit grey only.
  if (bits < 8)
    throw InputError(path, "is a " + std::to_string(bits) + "-bit grey PNG: captures must be 8-bit grey (2^" +
                               std::to_string(bits) + " grey levels cannot carry the laser lines' profile)");
  return image;
}

}  // namespace stereorig
