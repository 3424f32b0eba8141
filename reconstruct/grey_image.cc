#include "reconstruct/grey_image.h"

#include <cstdio>
#include <string>

#include "calib/core/input_error.h"
#include "reconstruct/image_file.h"

namespace stereorig {

cv::Mat ReadGreyImage(const std::string& path, std::optional<cv::Size> rig_size_px, long long max_pixels,
                      const std::string& why_max) {
  return ReadImageFile(path, [&](const ImageHeader& header) {
    // Says what the image is (a 16-bit grey, an RGB, a palette one), in
    // calibrate's and check's words (calib/capture_folder.cc), so that the
    // camera's setting to change is plain.
    if (header.channels != 1 || header.bit_depth != 8)
      throw InputError(path, "must be an 8-bit single-channel (grey) image (this one has " +
                                 std::to_string(header.channels) + " channel(s) of " +
                                 std::to_string(header.stored_bit_depth) + " bits)");
    // A 1-, 2- or 4-bit grey image (the decoder scales it to 8 bits) holds
    // 2-16 grey levels: the sub-pixel fit and the lit test read steps, not
    // the laser lines' profile (a 1-bit capture gave 0 points, a 4-bit one
    // silently fewer). Refused, as docs/formats.md says: 8-bit grey only.
    const int bits = header.stored_bit_depth;
    if (bits < 8)
      throw InputError(path, "is a " + std::to_string(bits) + "-bit grey PNG: captures must be 8-bit grey (2^" +
                                 std::to_string(bits) + " grey levels cannot carry the laser lines' profile)");
    if (rig_size_px && (header.width_px != rig_size_px->width || header.height_px != rig_size_px->height))
      throw InputError(path, "is " + std::to_string(header.width_px) + "x" + std::to_string(header.height_px) +
                                 ", the rig says " + std::to_string(rig_size_px->width) + "x" +
                                 std::to_string(rig_size_px->height));
    const long long pixels = static_cast<long long>(header.width_px) * header.height_px;
    // One decimal: 7072 x 7071 px read "50 Mpx, over the 50 Mpx" in whole
    // megapixels.
    auto MegapixelsText = [](long long n) {
      char text[32];
      std::snprintf(text, sizeof text, "%.1f", n / 1e6);
      return std::string(text);
    };
    if (max_pixels > 0 && pixels > max_pixels)
      throw InputError(path, "is " + std::to_string(header.width_px) + "x" + std::to_string(header.height_px) + " (" +
                                 MegapixelsText(pixels) + " Mpx), over the " + std::to_string(max_pixels / 1000000) +
                                 " Mpx " + why_max);
  });
}

}  // namespace stereorig
