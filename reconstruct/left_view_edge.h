// Dropping the left pixels whose refinement window reaches past the left
// view's own data.
//
// The rectified left image is zero where its remap source lies off the left
// sensor (a band along one side when the cameras are verged or the volume is
// off-centre). A Lucas-Kanade window (subpixel_refine.h) that holds some of
// those columns holds a step of ~100 DN from the surface to zero, the
// strongest feature in it, which the right image does not have at that
// place: the fit trades the laser lines' alignment against that step and
// ends up to a few pixels off with a high ZNCC. On the demo plate, which
// runs up to the edge of module 0's left view, those pixels were 0.37 % of
// the module's points but ~160-pixel clusters 0.4-2.1 mm off, and the
// module's std 0.084 mm instead of 0.071 (docs/reconstruct-log.md, session
// 18). The right view's edge is the other test in right_occlusion.h.
//
// The rule: a point is kept only if its refinement window, the
// (2 half_width + 1) x (2 half_height + 1) pixels about it (the sub-pixel
// step's window), has left data. No margin beyond the window: the gain
// (std) is all there at the window's own size, and each more column costs
// fill along the edge. Not covered: the wider windows growing may refine a
// pixel with instead (oblique_refine.h, up to 25 columns; shifted_window.h,
// to one side), which can still reach the zero fill from up to ~12 columns
// away; on the demo plate no cluster of errors was left there. Run before
// the right view's occlusion test (right_occlusion.h), so that these
// points do not hide correct ones as occluders.
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"

namespace stereorig {

// Sets the disparity of every valid pixel of `roi` whose window reaches a
// pixel of `left_valid` that is 0, or beyond the image, to +inf, its
// confidence to 0 and its status to PixelStatus::kLeftViewEdge.
// left_valid: CV_8UC1 the disparity map's size (ViewValidMask of the left
// remap tables), or empty (nothing is touched). Returns the pixels dropped.
int DropLeftViewEdge(const cv::Mat& left_valid, int half_width_px, int half_height_px, const cv::Rect& roi,
                     DisparityState* state);

}  // namespace stereorig
