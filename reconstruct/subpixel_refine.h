// Sub-pixel disparity refinement on image intensities, free of the
// peak-locking bias that a curve fit to integer-sampled matching costs has.
//
// A window of the left image is matched to the right image shifted by a
// continuous disparity with a gain and offset (Lucas-Kanade / Gauss-Newton on
// L(x+u, y+v) = a * R(x+u - d - gx*u - gy*v, y+v) + b). The disparity slopes
// gx, gy come from the integer-level disparity field and are held fixed: on
// a slanted or curved surface a pure shift would mis-model the window (0.03
// px error at 0.04 px/px; rejection on a sphere's flanks). The right row is
// interpolated with a tabulated Lanczos-3 kernel (a cubic leaves a +-0.02 px
// sawtooth on ~1 px wide laser lines). The fitted gain/offset make the result
// the ZNCC maximum, so exposure or speckle brightness differences between
// the cameras do not bias it.
#pragma once

#include <opencv2/core.hpp>

namespace stereorig {

struct SubpixelOptions {
  int half_width_px = 4;   // window half width along the row; default 4 (9 px: > one grid period)
  int half_height_px = 1;  // window half height; default 1 (3 rows)
  int max_iterations = 2;  // Gauss-Newton steps; default 2
  // Stop after a step smaller than this: from a start within ~0.2 px one
  // step leaves < 0.002 px of peak locking on the test pairs (measured), so
  // a second pass is only paid for when the first moved far. Default 0.05 px.
  double converged_step_px = 0.05;
  double max_shift_px = 1.0;  // refinement may move the start by at most this; default 1 px
  void Check() const;         // throws InputError naming the bad field
};

struct SubpixelResult {
  bool ok = false;  // converged inside the image and within max_shift_px
  double disparity_px = 0;
  double zncc = 0;    // normalised correlation of the fitted window, [-1, 1]
  double std_dn = 0;  // standard deviation of the left window, grey levels (texture)
  // Predicted 1-sigma of disparity_px, px: the least-squares covariance of
  // the last Gauss-Newton pass, (J^T J)^-1 [d, d] times the residual variance
  // e^T e / (n - 3) (n window pixels, 3 parameters). It is the Cramer-Rao
  // bound when the misfit is white noise (the synthetic pairs: matches the
  // scatter, subpixel_sigma_test.cc). On the simulator's captures the misfit
  // is mostly laser speckle, correlated over ~2 px and so over fewer
  // independent samples than n: the true scatter there is ~2-4x this
  // (a relative confidence, not an absolute one). 0 when the dense fit
  // (dense_refine.h) produced the result.
  double disparity_sigma_px = 0;
};

// left, right: CV_8UC1 rectified. (x, y): a left pixel; start_px: the
// disparity to start from (an integer-level match refined by a cost fit);
// slope_x, slope_y: dd/dx, dd/dy there (px/px).
SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                               double slope_y, const SubpixelOptions& options);

// ZNCC of the window at disparity d (no fit; the right window warped by the
// slopes as above, linearly interpolated). -1 if the window leaves either
// image.
double WindowZncc(const cv::Mat& left, const cv::Mat& right, int x, int y, double d, double slope_x, double slope_y,
                  const SubpixelOptions& options);

// The same fit with one more parameter: a vertical offset dy of the right
// window (rows y + v + dy; rows interpolated by a cubic convolution). On a
// correct match of a well rectified pair dy ~ 0. A match one laser-grid
// period off along the row aligns the near-vertical lines but leaves the
// near-horizontal ones (turned by the grid angle) offset vertically by about
// period * tan(angle): the vernier line_index.h reads. Up to
// options.max_iterations + 2 Gauss-Newton steps; |dy| <= 1 px.
struct RowOffsetResult {
  bool ok = false;
  double disparity_px = 0;
  double row_offset_px = 0;  // dy
  double zncc = 0;
};
RowOffsetResult RefineDisparityAndRowOffset(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px,
                                            double slope_x, double slope_y, const SubpixelOptions& options);

}  // namespace stereorig
