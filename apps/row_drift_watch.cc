#include "apps/row_drift_watch.h"

#include <vector>

namespace stereorig {

std::vector<RowDrift> RowDriftWatch::Add(const std::vector<ModuleReport>& modules) {
  std::vector<RowDrift> means;
  for (const ModuleReport& m : modules) {
    std::deque<RowDrift>& recent = recent_[m.module];
    if (m.row_drift.read) {
      recent.push_back(m.row_drift);
      if (int(recent.size()) > kCaptures) recent.pop_front();
    }
    const std::vector<RowDrift> window(recent.begin(), recent.end());
    RowDrift mean = MeanRowDrift(window);
    mean.warned = RowDriftWarned(mean, max_row_offset_px_);
    means.push_back(mean);
  }
  return means;
}

}  // namespace stereorig
