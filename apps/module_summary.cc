#include "apps/module_summary.h"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <vector>

namespace stereorig {

std::string LossLine(std::span<const int> counts_by_status, int total_px, int max_reasons) {
  std::vector<std::pair<int, size_t>> losses;  // (count, status)
  for (size_t k = 0; k < counts_by_status.size(); ++k)
    if (counts_by_status[k] && k != size_t(PixelStatus::kPoint)) losses.push_back({counts_by_status[k], k});
  std::sort(losses.rbegin(), losses.rend());
  const size_t shown = max_reasons > 0 ? std::min(losses.size(), size_t(max_reasons)) : losses.size();
  std::string line;
  char buf[64];
  for (size_t i = 0; i < shown; ++i) {
    std::snprintf(buf, sizeof buf, "%s%s %.1f%%", i ? ", " : "", PixelStatusName(PixelStatus(losses[i].second)),
                  100.0 * losses[i].first / std::max(1, total_px));
    line += buf;
  }
  if (shown < losses.size()) line += ", ...";
  return line;
}

std::string ModuleSummary(const ModuleReport& m, int max_reasons) {
  const auto match = m.times_ms.find("match");
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "module %d: %d points, fill %.1f%% of %d grid-lit px, match %.1f ms\n"
                "  searched d [%d, %d) of [%d, %d) px; lit px without a point: ",
                m.module, m.points, 100 * m.fill_rate(), m.lit_pixels, match == m.times_ms.end() ? 0.0 : match->second,
                m.searched_min_disparity_px, m.searched_min_disparity_px + m.searched_num_disparities,
                m.min_disparity_px, m.min_disparity_px + m.num_disparities);
  const std::string losses = LossLine(m.lit_by_status, m.lit_pixels, std::max(1, max_reasons));
  const std::string seen = m.seen_through > 0
                               ? "\n  " + std::to_string(m.seen_through) +
                                     " points removed, seen through (free_space_test; " +
                                     std::to_string(m.seen_through_surface) + " of them with their surface)"
                               : "";
  // No point at all where the grid lights pixels: most often the object is
  // not in the measurement volume (a rig used at another distance than the
  // defaults' 200 mm finds nothing, and exit 0 alone would not say why).
  const std::string nothing =
      m.points == 0 && m.lit_pixels > 0
          ? "\n  no point: if the object is not in the measurement volume, set working_distance_mm (or "
            "volume_center_mm, volume_size_mm) to where it is (docs/reconstruct.md, \"When the fill rate is low\")"
          : "";
  return buf + (losses.empty() ? "none" : losses) + seen + nothing;
}

}  // namespace stereorig
