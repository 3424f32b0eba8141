// A line's row drift: each module's readings (reconstruct/row_drift.h) over
// the recent captures of one batch or stream, so that a drift that persists
// is told from one capture's noise. A capture's reading alone has a
// standard error of ~0.02-0.03 px; the mean of 20 ~0.006.
//
// Sizes, not signed readings: the vernier's reading wraps every step (0.36
// px), so a module drifting past ~0.2 px reads either sign from capture to
// capture (a second reading, 0.25 px of rows over the demo's five scenes:
// -0.111, -0.098, +0.261, -0.081, -0.142): signed, they cancel; their sizes
// do not.
//
// Only sound readings count. A module whose matches reach an end of the
// volume's disparity range (ModuleReport::RangeEndsReached) may hold the
// laser grid matched a whole period off, a copy of itself inside the range,
// that the line index cannot move to its true period beyond the range: such
// a component reads a whole vernier step (0.36 px) off whatever the rows
// are. Measured: the tuber partly outside a volume at 210 mm, module 0 at
// 1.4 % fill reaching both ends, read -0.409 px (standard error 0.016)
// where every capture after it read within 0.067. Its reading is not
// counted (the capture's report says why, row_drift_run). A module with low
// fill but no range end still counts: the line index dropping most of a
// module as ambiguous is what a drift near half a step does.
//
// A warning stays for the rest of the run once the mean of a full window
// (kCaptures readings) gave it: a real drift does not go away by itself, and
// past ~0.2 px the module is a whole grid period off and its readings can
// come back small (docs/reconstruct.md, "Row drift"), so its going away
// would read as "fixed" where the module has broken. One reading a step off
// cannot make that mean warn (a calibrated module's sizes ~0.05 px: 0.05 +
// 2 x 0.36 / 20 = 0.086 px with two of them). A warning given on fewer
// readings (the run's first captures) is judged anew at each capture, as
// the mean of what there is, and withdrawn once that mean no longer warns:
// a false alarm from the run's first capture must not last the run.
#pragma once

#include <deque>
#include <map>
#include <string>
#include <vector>

#include "reconstruct/row_drift.h"
#include "reconstruct/runtime.h"

namespace stereorig {

struct WatchedRowDrift {
  // The mean size |row_offset_px| of the module's last counted readings (at
  // most RowDriftWatch::kCaptures; captures = how many), with the standard
  // error of that mean; not read where the module has none yet.
  RowDrift recent;
  // Why this capture's reading was not counted ("" if it was, or if the
  // module read nothing): "range_end_reached".
  std::string not_counted;
  bool warned = false;      // RowDriftWarned on `recent`, or a warning that stays (`stays`)
  bool stays = false;       // warned on a full window of readings at this or an earlier capture: for the run
  int warned_since = 0;     // the run's capture (1 = its first) at which this warning began; 0 = not warned
  bool started = false;     // warned at this capture and not at the one before
  int withdrawn_since = 0;  // not warned now, warned at the capture before since this capture; else 0
};

class RowDriftWatch {
 public:
  static constexpr int kCaptures = 20;  // the readings a module's mean is over, at most: the last ones

  explicit RowDriftWatch(double max_row_offset_px) : max_row_offset_px_(max_row_offset_px) {}

  // Adds one capture's sound readings (a module not read, or whose reading
  // is not sound, adds none) and returns each module's state, in the order
  // of `modules`.
  std::vector<WatchedRowDrift> Add(const std::vector<ModuleReport>& modules);

 private:
  struct Module {
    std::deque<RowDrift> recent;  // readings with row_offset_px made a size
    int warned_since = 0;
    bool stays = false;
  };
  double max_row_offset_px_;
  int captures_ = 0;
  std::map<int, Module> modules_;  // by module index
};

}  // namespace stereorig
