// Reading one image file the user gave, as stored (any depth and channel
// count): every way it can be unreadable is bad input (InputError) in one line
// naming the file, never OpenCV's or libpng's own lines on stderr. The one
// reader of reconstruct's image inputs: the grey captures
// (reconstruct/grey_image.h) and the simulator's truth maps
// (reconstruct/fill_score.h).
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <string>

namespace stereorig {

// The image at `path`, as cv::imread(path, IMREAD_UNCHANGED) gives it: a PNG
// decoded once, by calib/core/png_reader.h, or a float32 single-channel TIFF
// (CV_32FC1), by calib/core/float_tiff.h. No other format: the binary does
// not link OpenCV's imgcodecs (png_writer.h says why). Throws InputError if
// the file is missing or not a file, is a PNG cut short, damaged or too
// large (png_reader.h), is named .png but is not one, is a TIFF of another
// kind or damaged, or is neither. (The file's own bit depth, e.g. a grey
// PNG of 1, 2 or 4 bits the decoder scales to 8: the overload below.)
cv::Mat ReadImageFile(const std::string& path);

// What an image file's header says, before any pixel is decoded.
struct ImageHeader {
  int width_px = 0;
  int height_px = 0;
  int channels = 0;          // as decoded (png_reader.h: 1, 3 or 4)
  int bit_depth = 0;         // as decoded: 8 or 16 (PNG), 32 (float TIFF)
  int stored_bit_depth = 0;  // the file's own (PNG: 1, 2, 4, 8 or 16)
};

// ReadImageFile, with `check` called on the header before the pixels are
// allocated and decoded (PNG and float TIFF alike); it throws (InputError)
// to refuse the file. A capture image whose header gives another size than
// its camera's (a header declaring 16000 x 16000 px: 256 MB decoded, 2.7 s,
// before the size was compared) is refused in the time it takes to read its
// header.
cv::Mat ReadImageFile(const std::string& path, const std::function<void(const ImageHeader&)>& check);

}  // namespace stereorig
