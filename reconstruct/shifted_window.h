// Shifted refinement windows for pixels near an object's silhouette.
//
// A pixel within half a window of the silhouette has a centred window that
// straddles the background. Its two views of that edge differ (each camera
// sees the limb of a curved object at a different surface point, the
// background lies at another disparity), so the bright-to-dark step, the
// strongest feature of the window, does not follow the surface's disparity:
// the refinement fails or correlates poorly. Measured with `stereorig score
// --diagnose` on the simulator's scenes: a 1-2 px band around every
// silhouette is lost, which on the ball bar's thin rod is several % of the
// target.
//
// The classic remedy (shiftable windows) is to use a window that ends at the
// pixel instead of being centred on it: the window centred at x + k
// (|k| = the window's half width) covers x .. x + 2k and, with the local
// plane d(x + u) = d(x) + gx u + gy v that every refinement here assumes,
// gives d(x) = d(x + k) - gx k - gy l. The shifts are tried only for
// pixels whose centred refinement failed, in growing (region_grow.h), and the
// result is judged by the same tests (disparity_state.h) on the shifted
// window.
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"

namespace stereorig {

// Refines left pixel (x, y) from `predicted_px` (slopes gx, gy) with the
// window shifted towards `inward` (a unit step towards the surface already
// matched: (+-1, 0) shifts by the half width along the row, (0, +-1) by the
// half height across it), and returns kPoint if `accept` accepts it and its
// disparity at (x, y) lies within max_deviation_px of `predicted_px`, else
// the test that failed. `result->disparity_px` is the disparity at (x, y).
// One direction only: every extra window tried is one more chance for a
// wrong match to pass the tests.
PixelStatus RefineShiftedWindow(const cv::Mat& left, const cv::Mat& right, int x, int y, cv::Point inward,
                                double predicted_px, double slope_x, double slope_y, const RefineAcceptance& accept,
                                double max_deviation_px, SubpixelResult* result);

}  // namespace stereorig
