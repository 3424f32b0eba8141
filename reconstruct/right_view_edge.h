// Dropping the surfaces at the right view's edge whose laser line cannot be
// checked.
//
// A left pixel whose true match lies just outside the right view (the
// rectified right image's columns whose remap source is off the sensor) has
// nothing to find there, yet the matcher can give it the laser line one
// period over, inside the view: a patch a period off, ~3.5 mm at 200 mm.
// The occlusion test (right_occlusion.h) drops matches that land within
// `occlusion_margin_px` of the edge, not those a few pixels in. Every test
// that tells a period-off match from the right one (the distinctness test,
// the line index's vernier) compares it with the match a period over, and
// here that one lies off the view: nothing can be read.
//
// The rule: a valid pixel (x, y) with disparity d is unverifiable when the
// right columns x - d - (P + w) .. x - d + (P + w) hold one without data,
// or leave the image (P: the grid's period as the right view sees it,
// 2 DistinctnessShiftPx; w: the refinement window's half width). It is
// kept if its surface continues out of that zone: its connected component
// (4-neighbours whose disparities differ by at most max_step_px, the line
// index's components) holds a pixel outside the zone, where the line was
// checked. The components wholly inside the zone go.
//
// Measured (docs/reconstruct-log.md, session 24): on a fresh realization
// of the default plate (seed 6) module 0 kept 159 points 7-10 px off (up to
// 4 mm) in two strips beside the plate's left edge, where the right sensor
// ends; its std read 0.137 mm. The rule drops those 159 and no other point
// of that module; over 50 modules of five datasets it drops at most 16
// correct target pixels in a module (0.01 % of its target). The plate
// alone over 39 seeds (truth rig): modules above 0.1 mm std 2 -> 0.
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"
#include "reconstruct/right_occlusion.h"

namespace stereorig {

// Sets the disparity of every valid pixel of `roi` in a component the rule
// above drops to +inf, its confidence to 0 and its status to
// PixelStatus::kRightViewEdge. right_valid: CV_8UC1 the disparity map's
// size (ViewValidMask of the right remap tables), or empty (only the
// image's own columns bound the view). accept: the period
// (DistinctnessShiftPx, read with each pixel's state->slope_x) and the
// window's half width (accept.subpixel.half_width_px). max_step_px > 0.
// Returns the pixels dropped.
int DropUnverifiableAtRightViewEdge(const cv::Mat& right_valid, const RefineAcceptance& accept, double max_step_px,
                                    const cv::Rect& roi, DisparityState* state);
// The same with the right view's gaps already counted (right_occlusion.h;
// the matcher counts them once for this test and the occlusion test).
int DropUnverifiableAtRightViewEdge(const ViewGaps& right_gaps, const RefineAcceptance& accept, double max_step_px,
                                    const cv::Rect& roi, DisparityState* state);

}  // namespace stereorig
