// The board's size as the stored rig's stereo modules measure it, over the
// size the target file gives. A rig's own change (a camera turned, a module
// shifted, a lens drifted) moves one module's reading; a target file that is
// not the board's (another square size) scales every module's alike. The
// nightly check refuses the latter (RunNightlyCheck): judged against the
// wrong board, every camera read as changed and a false alarm went into the
// history (a user's walkthrough: a target file 2% too large).
#pragma once

#include <vector>

#include "calib/core/rig.h"
#include "calib/observations.h"
#include "targets/target.h"

namespace stereorig {

// How far every module's reading must be off (the same way) for the check
// to refuse the target file: 0.5%, well above what a rig's own change puts
// on one module (measured in board_scale_test.cc) and what its frame's
// thermal expansion puts on all (aluminium: 0.0023% per kelvin).
constexpr double kMaxBoardScaleOff = 0.005;

struct ModuleBoardScale {
  int module = -1;
  double scale = 1.0;  // measured size over the target file's: the median over the captures
  int captures = 0;    // captures in which both cameras saw one face with >= min_corners common corners
};

// Per module of `rig`: in each capture where its two cameras see the same
// face, the corners both see are triangulated with the stored calibration
// (TriangulatePair) and the similarity that best maps the face's grid of
// the target file onto them is fitted (Eigen's Umeyama); its scale, median
// over the captures. Modules without such a capture are left out.
std::vector<ModuleBoardScale> MeasureBoardScale(const Rig& rig, const Target& target,
                                                const std::vector<BoardObservation>& views, int min_corners = 6);

}  // namespace stereorig
