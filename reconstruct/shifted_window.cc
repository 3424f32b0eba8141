#include "reconstruct/shifted_window.h"

#include <cmath>

namespace stereorig {

PixelStatus RefineShiftedWindow(const cv::Mat& left, const cv::Mat& right, int x, int y, cv::Point inward,
                                double predicted_px, double slope_x, double slope_y, const RefineAcceptance& accept,
                                double max_deviation_px, SubpixelResult* result) {
  const cv::Point k(inward.x * accept.subpixel.half_width_px, inward.y * accept.subpixel.half_height_px);
  if (k.x == 0 && k.y == 0) return PixelStatus::kRefineFailed;
  const double along = slope_x * k.x + slope_y * k.y;  // d(x + k) - d(x) on the local plane
  SubpixelResult r;
  PixelStatus why = RefineAndAccept(left, right, x + k.x, y + k.y, predicted_px + along, slope_x, slope_y, accept, &r);
  r.disparity_px -= along;
  if (why == PixelStatus::kPoint && std::abs(r.disparity_px - predicted_px) > max_deviation_px)
    why = PixelStatus::kOffPlane;
  if (why == PixelStatus::kPoint) *result = r;
  return why;
}

}  // namespace stereorig
