// The board the nightly check measures with: the target file's, with the
// back_from_front the calibration ended with.
//
// Stage 3 of the calibration refines the target file's back_from_front (the
// plate's thickness and the faces' register) under the file's stated sigma,
// jointly with S, so S holds with that estimate and not with the file's. A
// module pair's closure composes S with back_from_front; measured with the
// file's, a board whose file is off by its own stated 1 sigma (0.01 mm per
// axis, the default's) read 0.019 mm against a threshold of 0.015 mm on an
// unmoved rig: "recalibrate" every night, the alarm nobody believes. The rig
// file records the board as calibrated (provenance.target, calib/core/rig.h),
// and the check uses that record.
#pragma once

#include <string>
#include <utility>

#include "calib/core/rig.h"
#include "targets/target.h"

namespace stereorig {

struct CheckTarget {
  explicit CheckTarget(Target board) : target(std::move(board)) {}
  Target target;                // the target file's board; back_from_front the calibration's where recorded
  bool as_calibrated = false;   // false: the rig file records no board (an older rig file); the file's back_from_front
  std::string calibrated_with;  // the record's target file (as calibrate was given it); empty without a record
  // The calibration's back_from_front against tonight's target file's: how
  // far stage 3 moved it (0 without a record or on a one-sided board).
  double calibrated_vs_file_mm = 0.0;
  double calibrated_vs_file_deg = 0.0;
  std::string note;  // what the user should know, for stdout and the report; empty when nothing
};

// Refuses (InputError naming `target_path` and the rig file) a board whose
// corners, square size or sides differ from the rig file's record: the
// rig's scale rests on the square size it was calibrated with, and its S on
// that board's faces. A target file whose back_from_front is not the one
// calibrated with (a re-measured plate, or another of the same print) is
// said in the note, not refused: the calibrated one is used either way.
CheckTarget TargetForCheck(const Rig& rig, const Target& file_target, const std::string& target_path);

}  // namespace stereorig
