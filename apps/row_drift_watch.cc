#include "apps/row_drift_watch.h"

#include <cmath>
#include <vector>

namespace stereorig {

std::vector<WatchedRowDrift> RowDriftWatch::Add(const std::vector<ModuleReport>& modules) {
  ++captures_;
  std::vector<WatchedRowDrift> states;
  for (const ModuleReport& m : modules) {
    std::deque<RowDrift>& recent = recent_[m.module];
    if (m.row_drift.read) {
      RowDrift size = m.row_drift;
      size.row_offset_px = std::abs(size.row_offset_px);
      recent.push_back(size);
      if (int(recent.size()) > kCaptures) recent.pop_front();
    }
    WatchedRowDrift state;
    state.recent = MeanRowDrift(std::vector<RowDrift>(recent.begin(), recent.end()));
    state.recent.warned = RowDriftWarned(state.recent, max_row_offset_px_);
    int& since = warned_since_[m.module];
    if (state.recent.warned && since == 0) since = captures_;
    state.warned = since > 0;
    state.warned_since = since;
    states.push_back(state);
  }
  return states;
}

}  // namespace stereorig
