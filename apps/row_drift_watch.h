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
//
// A module none of whose readings count is not watched at all: the part
// outside the volume for the whole run, or a volume set wrong, and each
// capture's report alone (row_drift_run.counted false) says so. The watch
// tells it once per run (WatchedRowDrift::unjudged), when the module's
// readings have gone kCaptures in a row not counted: as many captures as
// fill a window, where a module read at each would have been judged on a
// full one, warned for the run if it drifted. A line whose parts reach a
// range end now and then (the tuber, one capture in three, above) does not
// go 20 in a row. A run that ends before that with a module never counted
// is told at its end (Unjudged).
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
  // The module's readings not counted in a row up to this capture's, since
  // its last counted one or the run's start (a capture where it read
  // nothing is passed over), and those counted in the run before them.
  int not_counted_in_a_row = 0;
  int counted_before = 0;
  // This capture's reading made kCaptures not counted in a row, the first
  // time in the run: the module's drift has gone unjudged (said once a run).
  bool unjudged = false;
};

// A module whose drift went unjudged in a run (RowDriftWatch::Unjudged).
struct UnjudgedRowDrift {
  int module = 0;
  int unjudged_since = 0;  // the run's capture at which WatchedRowDrift::unjudged was given; 0 = not given
  int counted = 0;         // its readings counted in the run
  int not_counted = 0;     // and not counted (range_end_reached)
};

class RowDriftWatch {
 public:
  static constexpr int kCaptures = 20;  // the readings a module's mean is over, at most: the last ones

  explicit RowDriftWatch(double max_row_offset_px) : max_row_offset_px_(max_row_offset_px) {}

  // Adds one capture's sound readings (a module not read, or whose reading
  // is not sound, adds none) and returns each module's state, in the order
  // of `modules`.
  std::vector<WatchedRowDrift> Add(const std::vector<ModuleReport>& modules);

  // The modules whose drift went unjudged in the run so far, by module:
  // those given WatchedRowDrift::unjudged, and those none of whose readings
  // was counted (at least one read; unjudged_since 0 where the run has been
  // too short to give it: its end tells them).
  std::vector<UnjudgedRowDrift> Unjudged() const;

 private:
  struct Module {
    std::deque<RowDrift> recent;  // readings with row_offset_px made a size
    int warned_since = 0;
    bool stays = false;
    int counted = 0, not_counted = 0;  // readings in the run
    int not_counted_in_a_row = 0;
    int unjudged_since = 0;
  };
  double max_row_offset_px_;
  int captures_ = 0;
  std::map<int, Module> modules_;  // by module index
};

}  // namespace stereorig
