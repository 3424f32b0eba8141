// Reading one image file the user gave, as stored (any depth and channel
// count): every way it can be unreadable is bad input (InputError) in one line
// naming the file, never OpenCV's or libpng's own lines on stderr. The one
// reader of reconstruct's image inputs: the grey captures
// (reconstruct/grey_image.h) and the simulator's truth maps
// (reconstruct/fill_score.h).
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace stereorig {

// The image at `path`, as cv::imread(path, IMREAD_UNCHANGED) gives it: a PNG
// decoded once, by calib/core/png_reader.h, or a float32 single-channel TIFF
// (CV_32FC1), by calib/core/float_tiff.h. No other format: the binary does
// not link OpenCV's imgcodecs (png_writer.h says why). Throws InputError if
// the file is missing or not a file, is a PNG cut short, damaged or too
// large (png_reader.h), is named .png but is not one, is a TIFF of another
// kind or damaged, or is neither.
// *stored_bit_depth, if given: the PNG's own bit depth (PngReader::
// stored_bit_depth: 1, 2 or 4 for grey the decoder scaled to 8 bits); the
// TIFF's 32.
cv::Mat ReadImageFile(const std::string& path, int* stored_bit_depth = nullptr);

}  // namespace stereorig
