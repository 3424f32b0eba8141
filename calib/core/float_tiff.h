// Float32 single-channel TIFF files, read and written by libtiff: the
// simulator's truth depth maps (docs/formats.md, depth_camK.tiff). Written
// as cv::imwrite wrote them (uncompressed strips, 32-bit IEEE samples), so
// that datasets simulated before and after read alike; read from any strip
// layout and compression libtiff decodes. libtiff's own messages are kept,
// never printed: every failure is one InputError naming the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace stereorig {

struct FloatImage {
  uint32_t width_px = 0;
  uint32_t height_px = 0;
  std::vector<float> values;  // row-major, width_px x height_px
};

// True if `bytes` start as a TIFF file does ("II*\0" or "MM\0*"; BigTIFF's
// "II+\0" or "MM\0+").
bool StartsAsTiff(const std::string& bytes);

// The float32 single-channel TIFF at `path`. Throws InputError naming the
// file if it cannot be read or decoded, or holds another kind of image
// (its samples' type and count named), tiles, or more than
// kMaxFloatTiffPixels pixels. before_decoding (if given) is called with the
// image's size once its header is read and checked, before any sample is
// decoded or memory taken for them: a caller with a smaller limit (or one
// that wants no float image at all) throws there, so a small file declaring
// a huge image costs nothing.
inline constexpr uint64_t kMaxFloatTiffPixels = uint64_t(1) << 28;  // as PngReader::kMaxPixels
FloatImage ReadFloatTiff(const std::string& path,
                         const std::function<void(uint32_t width_px, uint32_t height_px)>& before_decoding = {});

// Writes `pixels` (height_px rows of width_px floats, row y at pixels +
// y * row_stride_bytes) to `path` as a float32 TIFF, in place (libtiff
// writes the file as it goes): callers pass a temporary path (the
// simulator writes into its temporary dataset folder). Throws InputError
// naming the file if it cannot be written.
void WriteFloatTiff(const std::string& path, uint32_t width_px, uint32_t height_px, const float* pixels,
                    size_t row_stride_bytes);

}  // namespace stereorig
