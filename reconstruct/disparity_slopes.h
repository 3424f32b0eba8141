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
// window, all of them on a line, or slopes no surface has (IsSurfaceSlope: a
// depth edge). Coordinates are disparity's own (column, row).
void DisparitySlopes(const cv::Mat& disparity, cv::Mat* slope_x, cv::Mat* slope_y, cv::Mat* plane);

// Whether a fitted plane's slopes (px/px) can be a surface's rather than a
// fit across a depth edge. Along the row the bound is one-sided, as the
// geometry is. A plane n . X = h_L (unit normal n, h_L > 0 the left
// camera's distance from it, rectified left-camera frame) has disparity
// d = B (n_x u + n_y v + n_z f) / h_L, so dd/dx = B n_x / h_L, and the
// right camera (at B along x) is h_R = h_L - B n_x from it: 1 - dd/dx =
// h_R / h_L, the width ratio of a patch in the right view to the left.
// The right camera sees the surface only if h_R > 0, so dd/dx < 1 (the
// bound leaves 0.5 px/px for the 9x9 fit's noise on steep flanks); but as
// the LEFT camera grazes the surface, h_L -> 0 and dd/dx -> -infinity. The
// plate at 60 degrees to a ring module's axis reads -1.6 px/px in that
// module, and under a bound of |dd/dx| <= 1.5 54 % of its target had no
// plane (docs/reconstruct-log.md, "The oblique plate (session 22)"; the
// speckle filter then takes the rest unless it follows the slopes,
// speckle_filter.h, RemoveSpeckleBlobsAlongSlopes). Across the
// rows there is no such asymmetry: |dd/dy| <= the same bound. Depth edges
// that pass are left to the plane test (max_plane_deviation_px): their
// pixels lie far off the fitted plane.
constexpr double kMaxSurfaceSlope = 1.5;
bool IsSurfaceSlope(double slope_x, double slope_y);

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
