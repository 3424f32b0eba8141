// A line's row drift: each module's readings (reconstruct/row_drift.h) over
// the recent captures of one batch or stream, so that a drift that persists
// is told from one capture's noise. A capture's reading alone has a
// standard error of ~0.02-0.03 px; the mean of 20 ~0.006.
//
// Sizes, not signed readings: the vernier's reading wraps every step (0.36
// px), so a module drifting past ~0.2 px reads either sign from capture to
// capture (a second reading, 0.25 px of rows over the demo's five scenes:
// -0.111, -0.098, +0.261, -0.081, -0.142): signed, they cancel; their sizes
// do not. And a warning stays for the rest of the run once given: past
// ~0.2 px the module is a whole grid period off and its readings can come
// back small (docs/reconstruct.md, "Row drift"), so its going away would
// read as "fixed" where the module has broken.
#pragma once

#include <deque>
#include <map>
#include <vector>

#include "reconstruct/row_drift.h"
#include "reconstruct/runtime.h"

namespace stereorig {

struct WatchedRowDrift {
  // The mean size |row_offset_px| of the module's last readings (at most
  // RowDriftWatch::kCaptures; captures = how many), with the standard error
  // of that mean; not read where the module has none yet.
  RowDrift recent;
  bool warned = false;   // RowDriftWarned on `recent`, now or at an earlier capture of the run
  int warned_since = 0;  // the run's capture (1 = its first) at which it was first warned; 0 = not warned
};

class RowDriftWatch {
 public:
  static constexpr int kCaptures = 20;  // the readings a module's mean is over, at most: the last ones

  explicit RowDriftWatch(double max_row_offset_px) : max_row_offset_px_(max_row_offset_px) {}

  // Adds one capture's readings (a module not read adds none) and returns
  // each module's state, in the order of `modules`.
  std::vector<WatchedRowDrift> Add(const std::vector<ModuleReport>& modules);

 private:
  double max_row_offset_px_;
  int captures_ = 0;
  std::map<int, std::deque<RowDrift>> recent_;  // by module index: readings with row_offset_px made a size
  std::map<int, int> warned_since_;             // by module index
};

}  // namespace stereorig
