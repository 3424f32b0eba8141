// Averaging the refined disparities over a neighbourhood wider than their
// error's correlation length, where a smooth surface explains them.
//
// Why: on the simulator's captures every refined disparity scatters by
// ~0.25-0.28 px (0.11 mm at the plate's 196 mm), nearly Gaussian and the same
// on every scene. It is laser speckle, independent in the two views: the
// sensor noise alone would allow 0.02-0.04 px (the Lucas-Kanade window's
// Cramer-Rao bound). A 9x3 window sees one or two lines over three rows, so
// its estimate carries the speckle of those few samples; neighbouring
// estimates share most of it (correlation 0.88 at 1 px, ~0 beyond 8 px along
// the row and 5 px across). Only more area lowers it: a wider window, or
// this fit of the estimates of many windows.
//
// What: each valid disparity is replaced by the value at its own pixel of a
// quadric d(u, v) = c0 + c1 u + c2 v + c3 u^2 + c4 u v + c5 v^2, fitted by
// least squares to the valid disparities of the (2 half_width + 1) x
// (2 half_height + 1) window around it (normalised convolution: the window
// sums of the 15 moments of the valid mask and the 6 of the disparities
// come from separable filters, then one 6x6 solve per pixel). A quadric, not
// a plane: a plane's value at the centre is biased by the surface's
// curvature (on the demo sphere a 15x9 plane fit is worse than none).
// The fit is kept only where it is trustworthy, else the pixel keeps its own
// disparity:
//   - the window is not degenerate: its centre's variance as the fit
//     predicts it for independent errors is at most max_variance_growth
//     times that of a full window (a 21x11 window cut by a silhouette
//     through its centre: 4.1x; only windows cut on two sides, near a
//     corner of the valid region, or holding a thin strip of pixels, go
//     further). Session 13 measured that a window cut by a silhouette or
//     a hole still beats the pixel's own value: the pixels at the edge of
//     the valid region are the worst of the module (their refinement
//     windows reach into what failed), and the fit's real scatter grows
//     far less than the independent-error prediction where the errors are
//     correlated over a few pixels. Raising the gate from 1.5 to 10 lowered
//     the std of every module of the four scored datasets (demo, seed 7,
//     speckle 0 and 0.4): default speckle by 0.0003-0.0043 mm, speckle 0.4
//     by 0.009-0.024 mm; fill unchanged (docs/reconstruct-log.md, "Fitted up to
//     the edges, and a wider window at strong speckle (session 13)");
//   - the quadric explains the window: the RMS misfit is at most
//     max_misfit_ratio times the median misfit over all fitted windows, or
//     0.05 px if that is more (a depth edge, two components one grid period
//     apart, or a surface curving faster than a quadric over the window
//     misfit far more).
// Stronger noise: where the module's median misfit exceeds
// reference_misfit_px (the scatter the window is sized for) by a ratio r, a
// second pass fits a window whose sides are larger by r^2 (capped at half
// sizes of 30 px); each pixel takes that fit where the same two tests
// trust it and its own window's fit is trusted, else its own window's.
// Why r^2 and not r (area with the variance, as independent errors would
// need): at twice the default speckle (r ~ 1.4) sides x r left every
// module's std 1.2-1.5x the default speckle's (the errors there are
// correlated over larger patches, ~30 px blobs on the plate); sides x r^2
// (41 x 21) brings all ten modules of the scored speckle-0.4 dataset to std
// 0.056-0.098 mm (another realization of the plate: 0.105 / 0.091, at the
// target rather than safely under it).
// Cost: the lateral detail finer than a quadric over the window (~4 x 2 mm
// at 200 mm by default, ~8 x 4 mm where the window grows at twice the
// default speckle) is smoothed away; the fill is unchanged. The second pass
// holds two more ROI-sized float images while it runs.
#pragma once

#include <opencv2/core.hpp>

namespace stereorig {

struct SurfaceFitOptions {
  bool enabled = true;     // default true
  int half_width_px = 10;  // window half width along the rows; default 10 (21 px: ~2.5 error correlation lengths)
  int half_height_px = 5;  // window half height; default 5 (11 rows: ~2 correlation lengths)
  // Largest predicted variance of the fitted centre, relative to a full
  // window's, for the fit to replace the pixel; default 10 (session 13;
  // was 1.5). A 21x11 window whose centre is 0 / 1 / 2 / 3 columns from a
  // silhouette: 4.1 / 2.3 / 1.6 / 1.3; 0 / 1 rows from one: 3.2 / 1.5.
  double max_variance_growth = 10;
  // Largest RMS misfit of the quadric over its window, relative to the
  // median over the module's windows; default 2.
  double max_misfit_ratio = 2.0;
  // The median misfit (px) the window above is sized for; default 0.2 (the
  // simulator's default speckle: 0.17-0.20 px on every scene and module).
  // Where a module's median misfit is larger (stronger speckle: 0.26-0.30
  // px at twice the default), a second pass fits a window whose sides are
  // larger by their ratio squared (41 x 21 there), and each pixel whose
  // own window's fit is trusted takes that fit where it is trusted too, else
  // its own window's. 0 = never.
  double reference_misfit_px = 0.2;
  void Check() const;  // throws InputError naming the bad field
};

// What a fit did, for the reconstruction report.
struct SurfaceFitSummary {
  int replaced = 0;             // pixels that took a fit
  double median_misfit_px = 0;  // of the options' window; 0 if nothing was fitted
  // The options' window, or the grown one when the second pass ran.
  int half_width_px = 0, half_height_px = 0;
};

// disparity_px: CV_32FC1, +inf (or NaN) = none; only `roi` is read and
// rewritten. Returns the number of pixels replaced by their fit; *summary
// (optional) gets that and the window and misfit behind it.
int FitLocalSurface(const cv::Rect& roi, const SurfaceFitOptions& options, int num_threads, cv::Mat* disparity_px,
                    SurfaceFitSummary* summary = nullptr);

}  // namespace stereorig
