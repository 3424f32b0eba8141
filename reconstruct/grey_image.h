// Reading one 8-bit grey image the user gave (a capture's camK.png, a
// rectified pair for `match`): every way it can be unreadable is bad input
// (InputError) in one line naming the file, never OpenCV's or libpng's own
// lines on stderr.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace stereorig {

// The image at `path`, CV_8UC1. Throws InputError if ReadImageFile
// (reconstruct/image_file.h) does (the file missing, a PNG cut short or
// damaged, one that cannot be decoded), or if it is not 8-bit single-channel
// (the message gives its channels and bits, as decoded: "this one has 3
// channel(s) of 8 bits" for RGB or a palette), a grey PNG of 1, 2 or 4 bits included (decoded scaled to 8 bits, but
// with 2-16 grey levels: the message names the file's depth), or, given `rig_size_px` (its camera's imager), if it is
// of another size ("is 16000x16000, the rig says 752x582"). All three are read from a PNG's header, before its pixels
// are allocated or decoded: a capture's decoded pixels cost at most its camera's size in memory, whatever its header
// declares (the file itself is read whole first: its bytes, not more).
// Given `max_pixels` (> 0), one of more pixels is refused from its header
// too, naming its size and `why_max` (what the cap is for).
cv::Mat ReadGreyImage(const std::string& path, std::optional<cv::Size> rig_size_px = std::nullopt,
                      long long max_pixels = 0, const std::string& why_max = "");

}  // namespace stereorig
