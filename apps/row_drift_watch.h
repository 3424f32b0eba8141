// A line's row drift: each module's readings (reconstruct/row_drift.h) over
// the recent captures of one batch or stream, so that a drift that persists
// is told from one capture's noise. A capture's reading alone has a
// standard error of ~0.02-0.03 px; the mean of 20 ~0.006, so a module drifting
// past the line index's tolerance is warned of on every capture once the
// mean is past it, and noise alone practically never.
#pragma once

#include <deque>
#include <map>
#include <vector>

#include "reconstruct/row_drift.h"
#include "reconstruct/runtime.h"

namespace stereorig {

class RowDriftWatch {
 public:
  static constexpr int kCaptures = 20;  // the readings a module's mean is over, at most: the last ones

  explicit RowDriftWatch(double max_row_offset_px) : max_row_offset_px_(max_row_offset_px) {}

  // Adds one capture's readings (a module not read adds none) and returns,
  // per module of `modules`, the mean of its last kCaptures readings, warned
  // by RowDriftWarned (not read where the module has none yet).
  std::vector<RowDrift> Add(const std::vector<ModuleReport>& modules);

 private:
  double max_row_offset_px_;
  std::map<int, std::deque<RowDrift>> recent_;  // by module index
};

}  // namespace stereorig
