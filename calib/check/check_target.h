// The board the nightly check measures with: the target file's, with the
// back_from_front the calibration ended with.
//
// Stage 3 of the calibration refines the target file's back_from_front (the
// plate's thickness and the faces' register) under the file's stated sigma,
// jointly with S, so S holds with that estimate and not with the file's. A
// module pair's closure and the cameras' consistency compose S with
// back_from_front; measured with the file's, a board whose file is off by
// its own stated 1 sigma (0.01 mm per axis, the default's) read 0.019 mm
// against a threshold of 0.015 mm on an unmoved rig: "recalibrate" every
// night, the alarm nobody believes. The rig file records the board as
// calibrated (provenance.target, calib/core/rig.h), and the check measures
// with that record while tonight's file is the same board and plate, and
// refuses another (TargetForCheck, below).
#pragma once

#include <string>
#include <utility>

#include "calib/core/rig.h"
#include "calib/plate_difference.h"
#include "targets/target.h"

namespace stereorig {

// A target file whose squares are within this of the record's is the same
// board, re-measured: 0.5 %, the board-size reading that names the wrong
// board (kMaxBoardScaleOff, board_scale.h); a print's scale is good to
// ~0.1 %. Beyond, another board.
inline constexpr double kSameBoardSquareOff = 0.005;
// A target file whose back_from_front differs from the one filed at
// calibration by no more than SamePlateChiSquare(axes)
// (calib/plate_difference.h; the axes judged, each over the two files'
// sigmas combined; an axis both hold at sigma 0 must not move) is the same
// plate. Beyond, another plate (or not the plate's file): refused.

struct CheckTarget {
  explicit CheckTarget(Target board) : target(std::move(board)) {}
  Target target;                // the board measured with (below)
  bool as_calibrated = false;   // false: the rig file records no board (an older rig file): the target file as it is
  std::string calibrated_with;  // the record's target file (its absolute path); empty without a record
  // back_from_front is the calibration's (the same plate); false: the target
  // file's (no record, or one side).
  bool back_from_front_as_calibrated = false;
  // The back_from_front measured with against tonight's target file's as
  // written: how far stage 3 moved it (0 when it is the file's).
  double calibrated_vs_file_mm = 0.0;
  double calibrated_vs_file_deg = 0.0;
  // Tonight's target file's back_from_front (its in-plane offset as written
  // or at the record's square size, the nearer) against the one filed at
  // calibration (0 without a record or on a one-sided board).
  double file_vs_filed_mm = 0.0;
  double file_vs_filed_deg = 0.0;
  std::string note;  // what the user should know, for stdout and the report; empty when nothing
};

// Refuses (InputError naming `target_path` and the rig file) a board whose
// corners or sides differ from the rig file's record, or whose squares do
// by more than kSameBoardSquareOff: the rig's scale rests on the squares it
// was calibrated with, and its S on that board's faces; and a plate whose
// back_from_front differs from the one filed at calibration beyond
// kSamePlateChiSquare: the check's thresholds (a few um) are finer than a
// plate's file (0.01 mm), and the calibration's estimate is of its own
// plate. The same board's squares re-measured are measured with the
// record's size (the rig's scale); its plate re-measured with the
// calibration's estimate; each said in the note.
CheckTarget TargetForCheck(const Rig& rig, const Target& file_target, const std::string& target_path);

}  // namespace stereorig
