// An image encoded as a PNG file's bytes, by libpng: what the simulator's
// captures and truth maps and score's diagnosis images are written as.
// With png_reader.h, this is why the `stereorig` binary does not link
// OpenCV's imgcodecs, whose Debian build loads ~100 further libraries (GDAL,
// GDCM, poppler, HDF5, ...) at every start: `stereorig --help` took
// 0.15-0.3 s and 56 MB, most of it the dynamic loader's, before any work
// (docs/reconstruct-log.md, "One binary without imgcodecs (session 34)").
//
// The pixels are laid out as cv::imwrite takes them, so that imread (and
// PngReader) gives them back byte for byte: grey; B, G, R; B, G, R, A; 8 or
// 16 bits a sample (16 in the machine's byte order).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace stereorig {

struct PngImage {
  uint32_t width_px = 0;
  uint32_t height_px = 0;
  int channels = 1;   // 1 grey, 3 B, G, R, 4 B, G, R, A
  int bit_depth = 8;  // 8 or 16
  const void* pixels = nullptr;
  size_t row_stride_bytes = 0;  // row y starts at pixels + y * row_stride_bytes
};

// The PNG file of `image`, deflated at `compression_level` (0 none, 1
// fastest, as the simulator writes its captures, ... 9 smallest). Throws
// std::invalid_argument for a layout PNG cannot hold as given (channels,
// bit depth, a side 0 or over libpng's 10^6 px: PngReader::kMaxSidePx) or a
// compression level outside [0, 9].
std::string EncodePng(const PngImage& image, int compression_level);

}  // namespace stereorig
