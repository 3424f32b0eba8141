#include "reconstruct/image_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>

#include "calib/core/file_suffix.h"
#include "calib/core/float_tiff.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/png_reader.h"

namespace stereorig {

namespace {

std::string FirstBytes(const std::string& path, size_t count) {
  std::ifstream f(path, std::ios::binary);
  std::string bytes(count, '\0');
  f.read(bytes.data(), std::streamsize(count));
  bytes.resize(size_t(f.gcount()));
  return bytes;
}

}  // namespace

cv::Mat ReadImageFile(const std::string& path) {
  return ReadImageFile(path, [](const ImageHeader&) {});
}

cv::Mat ReadImageFile(const std::string& path, const std::function<void(const ImageHeader&)>& check) {
  RequireInputFile(path);
  // Opened once here for the reason alone: the PNG reader's "cannot be
  // opened" leaves out why (permission denied, too many open files).
  if (FILE* f = std::fopen(path.c_str(), "rb"))
    std::fclose(f);
  else
    throw InputError(path, std::string("cannot be opened: ") + std::strerror(errno));
  // A PNG (every capture, the truth maps' id and lit maps) is decoded once,
  // by libpng, into the Mat imread would give.
  if (std::optional<PngReader> png = PngReader::Open(path)) {
    check({int(png->width_px()), int(png->height_px()), png->channels(), png->bit_depth(), png->stored_bit_depth()});
    cv::Mat image(int(png->height_px()), int(png->width_px()),
                  CV_MAKETYPE(png->bit_depth() == 16 ? CV_16U : CV_8U, png->channels()));
    png->Read(image.data, image.step);
    return image;
  }
  if (EndsWithIgnoringCase(path, ".png")) throw InputError(path, "is not a PNG file, though named .png");
  // The truth maps' depth: float32 TIFF, by libtiff.
  if (StartsAsTiff(FirstBytes(path, 4))) {
    // Checked from the header, before the samples are decoded: a 128 KB
    // TIFF declaring 16000 x 16000 floats took 2 GB before `match` refused
    // it as not 8-bit grey.
    FloatImage depth = ReadFloatTiff(path, [&](uint32_t width_px, uint32_t height_px) {
      check({int(width_px), int(height_px), 1, 32, 32});
    });
    cv::Mat image(int(depth.height_px), int(depth.width_px), CV_32FC1);
    std::copy(depth.values.begin(), depth.values.end(), image.ptr<float>());
    return image;
  }
  throw InputError(path,
                   "is neither a PNG nor a TIFF file (images are read as PNG; float32 TIFF for the simulator's depth "
                   "maps)");
}

}  // namespace stereorig
