// The local disparity plane of the integer-level disparity field: at each
// pixel, the least-squares plane d = c + gx x + gy y through the valid pixels
// of a 9x9 window. Averaging 81 samples of the ~0.1 px noisy field gives
// slopes good to ~0.005 px/px, so the sub-pixel window's model error is
// negligible (subpixel_refine.h); the plane is also the matcher's
// neighbourhood consistency test (max_plane_deviation_px, matcher.h).
//
// The plane's normal equations take the window sums of the valid mask's
// moments (1, x, y, x^2, y^2, x y: integers, summed exactly) and of the
// disparities' (d, x d, y d: summed in double). They are streamed down the
// map, 9 rows held at a time, straight into the fit: no map-sized
// intermediate (the nine box-filter images and their moment images this
// replaced were ~60 % of the runtime's page faults). The sums equal
// cv::boxFilter's to the bit wherever its double running sums are exact
// (disparities >= 2^-6 px, maps below 4096 px: beyond, its float images of
// x^2 were rounded and these sums stay exact), so the demo's clouds are
// byte-identical.
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

// The 9x9 window sums (zero outside the map) that DisparitySlopes fits, as
// maps: each CV_32FC1 of disparity.size(), the sum rounded once to float.
// x, y: disparity's column and row; d: the disparity (NaN: not in the sums).
// For tests and diagnostics; DisparitySlopes streams them row by row.
struct WindowMomentSums {
  cv::Mat n;   // valid pixels
  cv::Mat x;   // sum of x
  cv::Mat y;   // sum of y
  cv::Mat xx;  // sum of x^2
  cv::Mat yy;  // sum of y^2
  cv::Mat xy;  // sum of x y
  cv::Mat d;   // sum of d
  cv::Mat xd;  // sum of float(x d)
  cv::Mat yd;  // sum of float(y d)
};
WindowMomentSums WindowMomentSumMaps(const cv::Mat& disparity);

}  // namespace stereorig
