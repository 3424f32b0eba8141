#include "apps/row_drift_watch.h"

#include <cmath>
#include <vector>

namespace stereorig {

std::vector<WatchedRowDrift> RowDriftWatch::Add(const std::vector<ModuleReport>& modules) {
  ++captures_;
  std::vector<WatchedRowDrift> states;
  for (const ModuleReport& m : modules) {
    Module& watched = modules_[m.module];
    WatchedRowDrift state;
    const ModuleReport::RangeEnds ends = m.RangeEndsReached();
    state.counted_before = watched.counted;
    if (m.row_drift.read && (ends.near || ends.far)) {
      state.not_counted = "range_end_reached";
      ++watched.not_counted;
      if (++watched.not_counted_in_a_row == kCaptures && watched.unjudged_since == 0) {
        watched.unjudged_since = captures_;
        state.unjudged = true;
      }
    } else if (m.row_drift.read) {
      RowDrift size = m.row_drift;
      size.row_offset_px = std::abs(size.row_offset_px);
      watched.recent.push_back(size);
      if (int(watched.recent.size()) > kCaptures) watched.recent.pop_front();
      ++watched.counted;
      watched.not_counted_in_a_row = 0;
    }
    state.not_counted_in_a_row = watched.not_counted_in_a_row;
    state.recent = MeanRowDrift(std::vector<RowDrift>(watched.recent.begin(), watched.recent.end()));
    state.recent.warned = RowDriftWarned(state.recent, max_row_offset_px_);
    if (state.recent.warned && state.recent.captures >= kCaptures) watched.stays = true;
    state.stays = watched.stays;
    state.warned = state.recent.warned || watched.stays;
    if (state.warned && watched.warned_since == 0) {
      watched.warned_since = captures_;
      state.started = true;
    } else if (!state.warned && watched.warned_since != 0) {
      state.withdrawn_since = watched.warned_since;
      watched.warned_since = 0;
    }
    state.warned_since = watched.warned_since;
    states.push_back(state);
  }
  return states;
}

std::vector<UnjudgedRowDrift> RowDriftWatch::Unjudged() const {
  std::vector<UnjudgedRowDrift> unjudged;
  for (const auto& [module, watched] : modules_)
    if (watched.unjudged_since != 0 || (watched.counted == 0 && watched.not_counted > 0))
      unjudged.push_back({module, watched.unjudged_since, watched.counted, watched.not_counted});
  return unjudged;
}

}  // namespace stereorig
