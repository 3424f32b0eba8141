#include "reconstruct/disparity_state.h"

#include <algorithm>

#include "calib/core/input_error.h"
#include "reconstruct/subpixel_window.h"

namespace stereorig {

const char* PixelStatusName(PixelStatus status) {
  switch (status) {
    case PixelStatus::kNotSearched:
      return "not_searched";
    case PixelStatus::kPoint:
      return "point";
    case PixelStatus::kNoSgmMatch:
      return "no_sgm_match";
    case PixelStatus::kNoPlane:
      return "no_plane";
    case PixelStatus::kOffPlaneCoarse:
      return "off_plane_coarse";
    case PixelStatus::kRefineFailed:
      return "refine_failed";
    case PixelStatus::kLowZncc:
      return "low_zncc";
    case PixelStatus::kLowTexture:
      return "low_texture";
    case PixelStatus::kOutOfRange:
      return "out_of_range";
    case PixelStatus::kOffPlane:
      return "off_plane";
    case PixelStatus::kSpeckle:
      return "speckle";
    case PixelStatus::kNotDistinct:
      return "not_distinct";
    case PixelStatus::kLowConfidence:
      return "low_confidence";
    case PixelStatus::kOutsideVolume:
      return "outside_volume";
    case PixelStatus::kObjectSize:
      return "object_size";
    case PixelStatus::kOccluded:
      return "occluded";
    case PixelStatus::kWrongLine:
      return "wrong_line";
    case PixelStatus::kLeftViewEdge:
      return "left_view_edge";
    case PixelStatus::kSeenThrough:
      return "seen_through";
    case PixelStatus::kSeenThroughSurface:
      return "seen_through_surface";
    case PixelStatus::kRightViewEdge:
      return "right_view_edge";
    case PixelStatus::kNoGridLine:
      return "no_grid_line";
    case PixelStatus::kNumStatus:
      break;
  }
  return "?";
}

PixelStatus AcceptFit(const SubpixelResult& r, const RefineAcceptance& a) {
  if (!r.ok) return PixelStatus::kRefineFailed;
  if (r.zncc < a.min_zncc) return PixelStatus::kLowZncc;
  if (r.std_dn < a.min_texture_dn) return PixelStatus::kLowTexture;
  if (r.disparity_px < a.min_disparity_px || r.disparity_px > a.max_disparity_px) return PixelStatus::kOutOfRange;
  return PixelStatus::kPoint;
}

double DistinctnessShiftPx(double slope_x, const RefineAcceptance& a) {
  // The grid's period in the right view shrinks or grows with the
  // foreshortening: 1 - dd/dx of the left one's.
  return a.half_period_px * std::clamp(1.0 - slope_x, 0.3, 1.7);
}

namespace {

// The distinctness test of a fit that passed AcceptFit.
PixelStatus AcceptDistinct(const WindowZnccProbe& probe, double slope_x, const SubpixelResult& r,
                           const RefineAcceptance& a) {
  const double half = DistinctnessShiftPx(slope_x, a);
  // One window for both shifts, walked once for both (the second is needed
  // only if the first passes, on ~98 % of the pixels).
  double zncc[2];
  probe.AtPair(r.disparity_px + -half, r.disparity_px + half, zncc);
  for (const double z : zncc)
    if (r.zncc - z < a.min_distinctness) return PixelStatus::kNotDistinct;
  return PixelStatus::kPoint;
}

}  // namespace

PixelStatus Accept(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x, double slope_y,
                   const SubpixelResult& r, const RefineAcceptance& a) {
  const PixelStatus fit = AcceptFit(r, a);
  if (fit != PixelStatus::kPoint || !(a.min_distinctness > 0)) return fit;
  return AcceptDistinct(WindowZnccProbe(left, right, x, y, slope_x, slope_y, a.subpixel), slope_x, r, a);
}

PixelStatus RefineAndAccept(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                            double slope_y, const RefineAcceptance& a, SubpixelResult* result) {
  WindowSlot window;
  *result = RefineDisparity(left, right, x, y, start_px, slope_x, slope_y, a.subpixel, &window);
  const PixelStatus fit = AcceptFit(*result, a);
  if (fit != PixelStatus::kPoint || !(a.min_distinctness > 0)) return fit;
  // The fit's window near the right image's left edge is the portable
  // kind; the probe's is always the fastest (equal up to float rounding):
  // set one up as Accept does, so the outcome is the same.
  STEREORIG_CHECK(window.has_value());  // AcceptFit passes only fits that set a window up
  if (window->kernel() != WindowKernel::kFastest)
    return AcceptDistinct(WindowZnccProbe(left, right, x, y, slope_x, slope_y, a.subpixel), slope_x, *result, a);
  return AcceptDistinct(WindowZnccProbe(*window, slope_x, slope_y, a.subpixel), slope_x, *result, a);
}

}  // namespace stereorig
