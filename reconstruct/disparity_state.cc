#include "reconstruct/disparity_state.h"

#include <algorithm>

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

PixelStatus Accept(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x, double slope_y,
                   const SubpixelResult& r, const RefineAcceptance& a) {
  const PixelStatus fit = AcceptFit(r, a);
  if (fit != PixelStatus::kPoint) return fit;
  if (a.min_distinctness > 0) {
    const double half = DistinctnessShiftPx(slope_x, a);
    // One window for both shifts; the second is not needed once the first
    // fails (the test is on the larger of the two).
    const WindowZnccProbe probe(left, right, x, y, slope_x, slope_y, a.subpixel);
    for (const double shift : {-half, half})
      if (r.zncc - probe.At(r.disparity_px + shift) < a.min_distinctness) return PixelStatus::kNotDistinct;
  }
  return PixelStatus::kPoint;
}

}  // namespace stereorig
