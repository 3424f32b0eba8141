#include "reconstruct/grid_period_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>

#include "calib/core/input_error.h"

namespace stereorig {

std::vector<GridPeriodKey> SetGridPeriodKeys(double period_px, MatchOptions* o) {
  if (!(period_px >= kMinGridPeriodPx && period_px <= kMaxGridPeriodPx)) {
    char text[160];
    std::snprintf(text, sizeof text, "%.2f px is outside the %.0f-%.0f px the runtime's keys can serve", period_px,
                  kMinGridPeriodPx, kMaxGridPeriodPx);
    throw InputError("period", text);
  }
  const int p = int(std::lround(period_px));
  const MatchOptions defaults;
  std::vector<GridPeriodKey> keys;
  auto set = [&](const char* key, auto* field, double value) {
    keys.push_back({key, value, double(*field)});
    *field = static_cast<std::remove_reference_t<decltype(*field)>>(value);
  };
  set("grid_half_period_px", &o->grid_half_period_px, std::min(0.5 * p, kMaxGridHalfPeriodPx));
  set("line_index_max_shift_px", &o->line_index.max_shift_px, std::lround(1.5 * p));
  // ceil((p - 1) / 2) = floor(p / 2) for a whole p.
  set("line_index_window_half_height_px", &o->line_index.window_half_height_px,
      std::max(defaults.line_index.window_half_height_px, p / 2));
  set("line_index_footprint_gap_px", &o->line_index.footprint_gap_px, std::min(16, p));
  const int radius_rule_px = (p + 1) / 2 + 1;   // ceil(p / 2) + 1
  if (radius_rule_px > o->grid_line.radius_px)  // widening: only suggested (why: grid_period_options.h)
    keys.push_back({"grid_line_radius_px", double(o->grid_line.radius_px), double(o->grid_line.radius_px),
                    double(radius_rule_px)});
  else
    set("grid_line_radius_px", &o->grid_line.radius_px, radius_rule_px);
  return keys;
}

int OtherRoundedPeriodPx(double period_px) {
  const double below = std::floor(period_px);
  if (std::abs(period_px - (below + 0.5)) >= kRoundingMarginPx) return 0;
  const long nearest = std::lround(period_px);
  return int(nearest == long(below) ? below + 1 : below);
}

}  // namespace stereorig
