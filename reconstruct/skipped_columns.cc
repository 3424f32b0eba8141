#include "reconstruct/skipped_columns.h"

#include <algorithm>
#include <cmath>

#include "reconstruct/disparity_state.h"

namespace stereorig {

bool InterpolateSkippedColumn(const float* disparity_px, const float* confidence, const uint8_t* status, int x_left,
                              int x, int x_right, double slope_x, double* d_px, float* confidence_out) {
  const uint8_t point = uint8_t(PixelStatus::kPoint);
  if (status[x_left] != point || status[x_right] != point) return false;
  const double d_left = disparity_px[x_left], d_right = disparity_px[x_right];
  const double span_px = x_right - x_left;
  if (!(std::abs(d_right - d_left - slope_x * span_px) <= kMaxSkippedColumnJumpPx)) return false;
  const double w = (x - x_left) / span_px;
  *d_px = (1 - w) * d_left + w * d_right;
  *confidence_out = std::min(confidence[x_left], confidence[x_right]);
  return true;
}

}  // namespace stereorig
