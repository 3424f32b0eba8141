#include "apps/module_summary.h"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <vector>

namespace stereorig {

std::string ModuleSummary(const ModuleReport& m, int max_reasons) {
  const auto match = m.times_ms.find("match");
  char buf[256];
  std::snprintf(buf, sizeof buf, "module %d: %d points, fill %.1f%% of %d grid-lit px, match %.1f ms", m.module,
                m.points, 100 * m.fill_rate(), m.lit_pixels, match == m.times_ms.end() ? 0.0 : match->second);
  std::string s = buf;
  std::snprintf(buf, sizeof buf,
                "\n  searched d [%d, %d) of [%d, %d) px; lit px without a point:", m.searched_min_disparity_px,
                m.searched_min_disparity_px + m.searched_num_disparities, m.min_disparity_px,
                m.min_disparity_px + m.num_disparities);
  s += buf;
  std::vector<std::pair<int, int>> lost;  // (count, status)
  for (size_t k = 0; k < m.lit_by_status.size(); ++k)
    if (PixelStatus(k) != PixelStatus::kPoint && m.lit_by_status[k] > 0) lost.emplace_back(m.lit_by_status[k], int(k));
  std::sort(lost.begin(), lost.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  if (lost.empty()) return s + " none";
  const int shown = std::min(int(lost.size()), std::max(1, max_reasons));
  for (int i = 0; i < shown; ++i) {
    std::snprintf(buf, sizeof buf, "%s %s %.1f%%", i ? "," : "", PixelStatusName(PixelStatus(lost[i].second)),
                  100.0 * lost[i].first / std::max(1, m.lit_pixels));
    s += buf;
  }
  if (shown < int(lost.size())) s += ", ...";
  return s;
}

}  // namespace stereorig
