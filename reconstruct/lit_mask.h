// Which pixels the laser grid lights: the grey level's standard deviation
// over the 9x9 window around the pixel exceeds a contrast. The window is
// wider than the grid period, so the lit area is one solid region, and
// uniform dark or ambient-lit areas are not. The runtime crops the matching
// to the lit region's bounding box and counts fill over the lit pixels.
#pragma once

#include <opencv2/core.hpp>

namespace stereorig {

// grey: CV_8UC1 (may be a view; only its own pixels are read: the window
// is reflected at its edges, OpenCV's BORDER_REFLECT_101). Returns CV_8UC1
// of grey's size: 255 where mean(g^2) - mean(g)^2 over the 9x9 window, the
// two means rounded to float as cv::boxFilter rounds them and the variance
// formed in float, exceeds float(contrast_dn^2), else 0. The same bits as
// boxFilter of the float image and of its square, then `var > threshold`
// (the test checks it): the window sums of 8-bit values and their squares
// are integers (< 81 * 255^2), added exactly here in one pass.
cv::Mat LitMask(const cv::Mat& grey, double contrast_dn);

// Half the side of LitMask's window, px (9x9).
inline constexpr int kLitWindowHalfPx = 4;

// valid: CV_8UC1, 0 where a rectified view has no sensor data (its remap's
// zero fill; ModulePlan::left_valid). Returns CV_8UC1 of its size: 255
// where LitMask's whole window lies on sensor data (beyond the image's own
// edge counts as data: LitMask reflects there). A window over the step
// from the image to the zero fill has contrast of its own: a capture with
// the lasers off read as thousands of "grid-lit" pixels along the view's
// edge, and its summary blamed the refinement instead of the projector.
cv::Mat LitWindowOnData(const cv::Mat& valid);

}  // namespace stereorig
