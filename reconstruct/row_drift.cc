#include "reconstruct/row_drift.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace stereorig {

RowDrift ReadRowDrift(std::span<const VernierReading> readings) {
  RowDrift drift;
  std::vector<const VernierReading*> sorted;
  for (const VernierReading& r : readings)
    if (r.fits > 0 && r.pixels > 0 && std::isfinite(r.row_offset_px)) {
      sorted.push_back(&r);
      drift.pixels += r.pixels;
    }
  if (sorted.empty()) return RowDrift{};
  std::stable_sort(sorted.begin(), sorted.end(), [](const VernierReading* a, const VernierReading* b) {
    return a->row_offset_px < b->row_offset_px;
  });
  // The reading holding pixel (pixels - 1) / 2 in that order.
  const long middle = (long(drift.pixels) - 1) / 2;
  long below = 0;
  for (const VernierReading* r : sorted) {
    below += r->pixels;
    if (below > middle) {
      drift.row_offset_px = r->row_offset_px;
      drift.standard_error_px = r->standard_error_px;
      break;
    }
  }
  drift.read = true;
  drift.components = int(sorted.size());
  drift.captures = 1;
  return drift;
}

RowDrift MeanRowDrift(std::span<const RowDrift> drifts) {
  RowDrift mean;
  double sum = 0, sum_var = 0;
  for (const RowDrift& d : drifts) {
    if (!d.read) continue;
    sum += d.row_offset_px;
    sum_var += d.standard_error_px * d.standard_error_px;
    mean.components += d.components;
    mean.pixels += d.pixels;
    ++mean.captures;
  }
  if (mean.captures == 0) return RowDrift{};
  mean.read = true;
  mean.row_offset_px = sum / mean.captures;
  mean.standard_error_px = std::sqrt(sum_var) / mean.captures;
  return mean;
}

bool RowDriftWarned(const RowDrift& drift, double max_row_offset_px) {
  const double off = std::abs(drift.row_offset_px);
  return drift.read && off > max_row_offset_px && off > 4 * drift.standard_error_px;
}

}  // namespace stereorig
