// The Lucas-Kanade sub-pixel fit of subpixel_refine.h done densely: for all
// pixels of a region at once, with the per-pixel path as the fallback.
//
// RefineDisparity samples, for each window, the right image along the
// window's own plane d + gx u + gy v (27 windows overlap at every pixel, so
// each right sample is interpolated 27 times). Here each Gauss-Newton pass
// warps the right image once by the current disparity field F (the same
// Lanczos-3 taps, lanczos_taps.h), forms the per-pixel products the normal
// equations need, sums them over the window with separable box sums
// (window_sums.h) and solves the 3x3 system (disparity, gain, offset) per
// pixel. The gain and offset enter the sums algebraically, so 8 window sums
// serve every pixel's system.
//
// That is the per-pixel fit exactly where F is, over each window, the
// window's plane. The field starts as the local disparity plane
// (DisparitySlopes' 9x9 fit: smooth); after a pass it is that plane plus a
// local mean of the pixels' corrections, so the last pass deviates from a
// window's plane by the remaining noise of those means. The plane is the
// field's own least-squares plane over the window: the refined field's
// slopes, not DisparitySlopes' (those, from the integer-level field, are off
// by ~0.03-0.05 px/px on curved flanks, where the per-pixel model is off by
// as much; holding the dense fit to them sent ~80% of the cup's pixels back
// to the per-pixel fit). A pixel's dense result is kept only if
//   - every pixel of its window has a field value (inside the image, a plane);
//   - the field's RMS residual from its window's plane is at most
//     kMaxWarpDeviationPx: to first order the result then moves by a
//     weighted mean of those residuals, so by about that;
//   - the last step was below converged_step_px (so the last pass's
//     linearisation point, shared by the window, was already close), gain
//     > 0, and the result is within max_shift_px of the start and inside
//     RefineDisparity's reach.
// Every other pixel is left to RefineDisparity (ok = false below).
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/subpixel_refine.h"

namespace stereorig {

// The largest RMS residual of the warp field from a window's plane for
// which the dense result stands in for the per-pixel one, px: about twice
// the fit's noise on the synthetic laser grid, a tenth of a cost fit's error.
constexpr double kMaxWarpDeviationPx = 0.04;

struct DenseRefineResult {
  cv::Rect roi;          // the region refined, in the left image
  cv::Mat disparity_px;  // CV_32FC1, roi.size(): the refined disparity
  cv::Mat zncc;          // CV_32FC1: as SubpixelResult::zncc
  cv::Mat std_dn;        // CV_32FC1: as SubpixelResult::std_dn
  cv::Mat ok;            // CV_8UC1: 1 = the dense fit stands; 0 = refine this pixel by RefineDisparity
  int num_dense = 0;     // pixels with a start and ok = 1
  int num_fallback = 0;  // pixels with a start and ok = 0

  // The dense result at left pixel (x, y) as RefineDisparity's result
  // (ok = false: not dense, use the per-pixel path).
  SubpixelResult At(int x, int y) const;
};

// left, right: CV_8UC1 rectified. roi: left-image region. start_px: CV_32FC1
// of roi.size(), the cost-fit disparities (NaN = no match; only these pixels
// count in num_dense / num_fallback, but every pixel with a plane is
// refined, as a neighbour). plane_px, slope_x, slope_y: CV_32FC1 of
// roi.size(), the local disparity plane at each pixel and its slopes (px,
// px/px; plane NaN = none).
DenseRefineResult DenseRefine(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const cv::Mat& start_px,
                              const cv::Mat& plane_px, const cv::Mat& slope_x, const cv::Mat& slope_y,
                              const SubpixelOptions& options, int num_threads);

}  // namespace stereorig
