#include "reconstruct/grey_image.h"

#include <fstream>

#include "calib/core/input_error.h"
#include "reconstruct/image_file.h"

namespace stereorig {

namespace {

// The bit depth a grey PNG stores its samples in (IHDR's bit depth, byte
// 24, when the colour type, byte 25, is 0: grey), or 0 for anything else.
// The decoder scales 1-, 2- and 4-bit grey to 8 bits (png_reader.h), so
// the decoded image alone cannot tell such a file from an 8-bit one.
int StoredGreyBitDepth(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  char header[26] = {};
  if (!f.read(header, sizeof header)) return 0;
  return header[25] == 0 ? int(static_cast<unsigned char>(header[24])) : 0;
}

}  // namespace

cv::Mat ReadGreyImage(const std::string& path) {
  cv::Mat image = ReadImageFile(path);
  if (image.type() != CV_8UC1) throw InputError(path, "must be an 8-bit single-channel (grey) image");
  // A 1-, 2- or 4-bit grey image holds 2-16 grey levels: the sub-pixel fit
  // and the lit test read steps, not the laser lines' profile (a 1-bit
  // capture gave 0 points, a 4-bit one silently fewer). Refused, as
  // docs/formats.md says: 8-bit grey only.
  if (const int bits = StoredGreyBitDepth(path); bits > 0 && bits < 8)
    throw InputError(path, "is a " + std::to_string(bits) + "-bit grey PNG: captures must be 8-bit grey (2^" +
                               std::to_string(bits) + " grey levels cannot carry the laser lines' profile)");
  return image;
}

}  // namespace stereorig
