#include "reconstruct/image_file.h"

#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/png_reader.h"

namespace stereorig {

cv::Mat ReadImageFile(const std::string& path) {
  // Missing: imread would print OpenCV's own warning first.
  RequireInputFile(path);
  // A PNG (every capture, the truth maps' id and lit maps) is decoded once,
  // by libpng, into the Mat imread would give.
  if (std::optional<PngReader> png = PngReader::Open(path)) {
    cv::Mat image(int(png->height_px()), int(png->width_px()),
                  CV_MAKETYPE(png->bit_depth() == 16 ? CV_16U : CV_8U, png->channels()));
    png->Read(image.data, image.step);
    return image;
  }
  // Named .png but holding another format: its decoder would print its own
  // complaint (libjpeg's "Premature end of JPEG file") before ours.
  if (EndsWithIgnoringCase(path, ".png")) throw InputError(path, "is not a PNG file, though named .png");
  // Any other format imread reads (the truth maps' depth, TIFF).
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {  // e.g. a header whose size the decoder refuses
    // e.err alone: e.msg adds OpenCV's version, source file and a newline.
    throw InputError(path, "cannot read the image (" + e.err + ")");
  }
  if (image.empty()) throw InputError(path, "cannot read the image (not an image, or a damaged one)");
  return image;
}

}  // namespace stereorig
