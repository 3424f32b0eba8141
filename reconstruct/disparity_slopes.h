// The local disparity plane of the integer-level disparity field: at each
// pixel, the least-squares plane d = c + gx x + gy y through the valid pixels
// of a 9x9 window. Averaging 81 samples of the ~0.1 px noisy field gives
// slopes good to ~0.005 px/px, so the sub-pixel window's model error is
// negligible (subpixel_refine.h); the plane is also the matcher's
// neighbourhood consistency test (max_plane_deviation_px, matcher.h).
//
// The plane's normal equations take the window sums of the valid mask's
// moments (1, x, y, x^2, y^2, x y: integers) and of the disparities' (d, x d,
// y d). The six integer ones are summed exactly in integer arithmetic, all
// in one pass (WindowMaskMomentSums); the three others by cv::boxFilter. Its
// double running sums of integers are exact too, so the six equal
// cv::boxFilter's to the bit, and the planes those of nine box filters (the
// demo's clouds are byte-identical), at less cost: the box filters were
// ~60 % of this step's instructions, and the step runs on one thread before
// the per-pixel fit. (To the bit for maps below 4096 px: beyond, the box
// filters' float images of x^2 were rounded; these sums stay exact.)
#pragma once

#include <opencv2/core.hpp>

namespace stereorig {

constexpr int kSlopeWindowHalfPx = 4;  // the window: 9 x 9 px

// disparity: CV_32FC1, NaN = no match.
// slope_x, slope_y: CV_32FC1 of disparity.size() (may be views into larger
// maps), overwritten with dd/dx, dd/dy (px/px), 0 where there is no plane.
// *plane: set to CV_32FC1 of disparity.size(), the plane's disparity at each
// pixel (px), NaN where there is none: fewer than 12 valid pixels in the
// window, all of them on a line, or a slope above 1.5 px/px (a depth edge,
// not a surface). Coordinates are disparity's own (column, row).
void DisparitySlopes(const cv::Mat& disparity, cv::Mat* slope_x, cv::Mat* slope_y, cv::Mat* plane);

// The 9x9 window sums (zero outside the map) of the valid mask's moments at
// each pixel: each CV_32FC1 of disparity.size(), the exact integer sum
// rounded once to float. x, y: disparity's column and row.
struct MaskMomentSums {
  cv::Mat n;   // valid pixels
  cv::Mat x;   // sum of x
  cv::Mat y;   // sum of y
  cv::Mat xx;  // sum of x^2
  cv::Mat yy;  // sum of y^2
  cv::Mat xy;  // sum of x y
};
MaskMomentSums WindowMaskMomentSums(const cv::Mat& disparity);

}  // namespace stereorig
