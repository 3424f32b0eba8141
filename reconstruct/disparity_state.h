// The matcher's per-pixel state after the SGM and sub-pixel passes, shared by
// the steps that revise it (line_index.h, region_grow.h), and the test that
// accepts a refined disparity.
#pragma once

#include <limits>
#include <opencv2/core.hpp>

#include "reconstruct/subpixel_refine.h"

namespace stereorig {

// What became of each left pixel: a point, or the first test that rejected
// it. The matcher sets the codes up to kNotDistinct and kOccluded,
// kWrongLine, kLeftViewEdge, kRightViewEdge, kNoGridLine; the runtime adds kLowConfidence, kOutsideVolume, kObjectSize,
// kSeenThrough, kSeenThroughSurface. For finding where fill is lost (`stereorig score` tabulates them).
enum class PixelStatus : uint8_t {
  kNotSearched = 0,     // outside the matched region
  kPoint,               // a valid disparity (and, in the runtime, a kept point)
  kNoSgmMatch,          // SGM: left-right check, uniqueness, or the best cost at the range's edge
  kNoPlane,             // too few valid neighbours for the local plane, or a depth edge
  kOffPlaneCoarse,      // the cost-fit disparity is off the local plane (before refinement)
  kRefineFailed,        // sub-pixel refinement diverged, moved too far, or left the image
  kLowZncc,             // refined window correlates below min_zncc
  kLowTexture,          // window std below min_texture_dn
  kOutOfRange,          // refined disparity outside the searched range
  kOffPlane,            // refined disparity off the local plane
  kSpeckle,             // in a blob smaller than speckle_window_px
  kNotDistinct,         // correlates about as well half a grid period off (RefineAcceptance)
  kLowConfidence,       // runtime: confidence below min_confidence
  kOutsideVolume,       // runtime: triangulated outside the measurement volume
  kObjectSize,          // runtime: farther than object_size_mm from the module cloud's median
  kOccluded,            // its match in the right view is hidden by a nearer surface, or outside it (right_occlusion.h)
  kWrongLine,           // in a component on the wrong laser line that no whole-period move fixes (line_index.h)
  kLeftViewEdge,        // its refinement window reaches past the left view's data (left_view_edge.h)
  kSeenThrough,         // runtime: other modules' surfaces facing this camera lie in front of it (free_space.h)
  kSeenThroughSurface,  // runtime: on a surface the free-space test found mostly seen through, removed whole
  kRightViewEdge,       // in a surface at the right view's edge whose line cannot be checked (right_view_edge.h)
  kNoGridLine,          // no laser line near it: its match rests on shading or an outline (grid_line_support.h)
  kNumStatus
};
const char* PixelStatusName(PixelStatus status);

// All CV_*C1 of the left image's size.
struct DisparityState {
  cv::Mat disparity_px;  // CV_32F: px, +inf = none
  cv::Mat confidence;    // CV_32F: ZNCC of the refined window, 0 = none
  cv::Mat status;        // CV_8U: PixelStatus
  cv::Mat slope_x;       // CV_32F: dd/dx of the local disparity plane, px/px (0 where unknown)
  cv::Mat slope_y;       // CV_32F: dd/dy
};

// Withdraws the point at left pixel (x, y), for the reason `why`: no
// disparity (+inf), confidence 0, status `why`. How the tests after the
// match (and the line index's re-refinement) drop a point, so the three
// maps always agree.
inline void DropPoint(int x, int y, PixelStatus why, DisparityState* state) {
  state->disparity_px.at<float>(y, x) = std::numeric_limits<float>::infinity();
  state->confidence.at<float>(y, x) = 0;
  state->status.at<uint8_t>(y, x) = uint8_t(why);
}

// When a Lucas-Kanade refinement (subpixel_refine.h) counts as a match.
struct RefineAcceptance {
  SubpixelOptions subpixel;
  double min_zncc = 0.8;        // the matcher's min_zncc
  double min_texture_dn = 1.5;  // the matcher's min_texture_dn
  double min_disparity_px = 0;  // the searched range, px
  double max_disparity_px = 0;
  // The match must be distinct: its ZNCC must beat the (unrefined) ZNCC
  // half a grid period either side by min_distinctness. A smooth shading
  // ramp (an unlit surface) correlates at any shift, and a window half off
  // the lit region lines up its few lines about as well a few px off; a
  // grid-lit window decorrelates half a period off. 0 = off.
  double min_distinctness = 0.4;
  double half_period_px = 4;  // the shift of that test, px (the default rig's grid: ~8 px period)
};

// The tests on the fit alone (converged, ZNCC, texture, range): kPoint or
// the test `r` fails. Shared by the per-pixel and dense fits (dense_refine.h).
PixelStatus AcceptFit(const SubpixelResult& r, const RefineAcceptance& a);

// The shift of the distinctness test at a pixel whose disparity slope along
// the row is slope_x: half a grid period as the right view sees it, px.
double DistinctnessShiftPx(double slope_x, const RefineAcceptance& a);

// kPoint if the refinement `r` of left pixel (x, y) (slopes as refined) is a
// match by `a`, else the test it fails: AcceptFit, then the distinctness
// test (WindowZncc DistinctnessShiftPx either side).
PixelStatus Accept(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x, double slope_y,
                   const SubpixelResult& r, const RefineAcceptance& a);

// RefineDisparity(left, right, x, y, start_px, slope_x, slope_y,
// a.subpixel) into *result, then Accept of it: the same outcome, with the
// window's set-up (left values, sample offsets) done once for the fit and
// the distinctness test (it was ~10 % of the sub-pixel step's instructions
// when done twice).
PixelStatus RefineAndAccept(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                            double slope_y, const RefineAcceptance& a, SubpixelResult* result);

}  // namespace stereorig
