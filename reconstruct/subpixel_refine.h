// Sub-pixel disparity refinement on image intensities, free of the
// peak-locking bias that a curve fit to integer-sampled matching costs has.
//
// A window of the left image is matched to the right image shifted by a
// continuous disparity with a gain and offset (Lucas-Kanade / Gauss-Newton on
// L(u,v) = a * R(u - d, v) + b). The right row is interpolated with the
// Catmull-Rom cubic, whose error for the ~8 px laser-line period is far below
// the noise; the fitted gain/offset make the result the ZNCC maximum, so the
// two cameras' different exposure or laser speckle brightness do not bias it.
#pragma once

#include <opencv2/core.hpp>

namespace stereorig {

struct SubpixelOptions {
  int half_width_px = 4;    // window half width along the row; default 4 (9 px: > one grid period)
  int half_height_px = 1;   // window half height; default 1 (3 rows)
  int max_iterations = 4;   // Gauss-Newton steps; default 4 (the start is within ~0.3 px)
  double max_shift_px = 1.0;  // refinement may move the start by at most this; default 1 px
  void Check() const;       // throws InputError naming the bad field
};

struct SubpixelResult {
  bool ok = false;     // converged inside the image and within max_shift_px
  double disparity_px = 0;
  double zncc = 0;     // normalised correlation of the fitted window, [-1, 1]
  double std_dn = 0;   // standard deviation of the left window, grey levels (texture)
};

// left, right: CV_8UC1 rectified. (x, y): a left pixel; start_px: the
// disparity to start from (an integer-level match refined by a cost fit).
SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px,
                               const SubpixelOptions& options);

}  // namespace stereorig
