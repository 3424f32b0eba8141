// PFM (Portable Float Map) reading and writing, for disparity maps.
//
// The format: a text header "Pf\n<width> <height>\n<scale>\n" then
// width*height 32-bit floats, one channel, rows stored BOTTOM to TOP. A
// negative scale means little-endian data; we always write scale -1 and read
// either byte order. Invalid disparities are stored as +inf, the convention
// the Middlebury stereo tools use.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace stereorig {

// Encodes a CV_32FC1 image (row 0 = top of the image) as PFM bytes.
std::string EncodePfm(const cv::Mat& image_f32);
// Decodes PFM bytes ("Pf" grey only) into a CV_32FC1 image, row 0 = top.
// Throws InputError(where, ...) on a malformed header or short data.
cv::Mat DecodePfm(const std::string& bytes, const std::string& where);

// File forms. Writing is atomic; reading throws InputError naming the file.
// WritePfm throws InputError unless `path` ends in .pfm, in any case
// (CheckPfmPath).
void WritePfm(const cv::Mat& image_f32, const std::string& path);
// Throws InputError unless `path` ends in .pfm: "disp.png" or "disp.tiff"
// would otherwise hold PFM bytes an image viewer cannot open. Commands call
// it before any work.
void CheckPfmPath(const std::string& path);
cv::Mat ReadPfm(const std::string& path);

}  // namespace stereorig
