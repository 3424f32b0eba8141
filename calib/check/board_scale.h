// The board's size as the stored rig's stereo modules measure it, over the
// size the target file gives. A target file that is not the board's
// (another square size) scales every module's reading alike; a camera
// turned moves its own module's (0.5 deg: +1.0 to +1.3%), a lens drift or a
// module's shift barely any. The nightly check says so when every module
// reads the board off alike (CheckResult::board_size_note): judged against
// the wrong board every camera read as changed, with no word of the board
// (a user's walkthrough: a target file 2% too large).
#pragma once

#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "calib/observations.h"
#include "targets/target.h"

namespace stereorig {

// How far every module's reading must be off (the same way) for the check
// to name the board: 0.5%, 25 times the scatter with the right file (0.02%
// on the default rig, NightlyCheck.AWrongTargetFileIsNamedAndABumpIsNot)
// and far beyond a frame's thermal expansion (aluminium: 0.0023% per
// kelvin). One camera turned 0.2 deg reads so too, on its own module only.
constexpr double kMaxBoardScaleOff = 0.005;

struct ModuleBoardScale {
  int module = -1;
  double scale = 1.0;  // measured size over the target file's: the (lower) median over the captures
  int captures = 0;    // captures in which both cameras saw one face with >= min_corners common corners
};

// Per module of `rig`: in each capture where its two cameras see the same
// face, the corners both see are triangulated with the stored calibration
// (TriangulatePair) and the similarity that best maps the face's grid of
// the target file onto them is fitted (Eigen's Umeyama); its scale, median
// over the captures. Modules without such a capture are left out.
std::vector<ModuleBoardScale> MeasureBoardScale(const Rig& rig, const Target& target,
                                                const std::vector<BoardObservation>& views, int min_corners = 6);

// What the readings say of the board: when every module of the rig (at
// least two, each read from 3 captures or more) reads it off the same way by
// more than kMaxBoardScaleOff, and by the same within half the smaller, "every
// module measures the board smaller than squares of 9.180 mm (module 0
// -1.96%, module 1 -1.96%): ..."; otherwise empty. square_size_mm: the
// squares the check measured with (the target file's or the rig file's
// record of them, check_target.h). With
// one module a board of another size cannot be told from the module's own
// change: empty.
std::string BoardSizeNote(const std::vector<ModuleBoardScale>& scales, int num_modules, double square_size_mm);

}  // namespace stereorig
