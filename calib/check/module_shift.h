// A module that moved as a whole while a lens of it changed too. Its two
// cameras then disagree with each other (the lens) and both with the other
// modules (the shift), and naming them one by one read each as changed:
// the unchanged partner "moved" by the module's shift (camera 0's principal
// point +1 px with module 1 0.5 mm off: cameras 0 and 1 "moved", 0.506 and
// 0.495 mm), and the module's shift, which only a closure would show, was
// not named (a closure is not judged for a module whose cameras disagree).
//
// Fitted to both cameras' corners, with the board poses the other modules
// imply held fixed: one shift of the module in the reference frame (3
// parameters, both cameras alike) and each camera's lens (focal length, fx
// and fy by one factor, and principal point: 3 each, as camera_change.h's
// lens fit). A turn of the module is left to the lenses: a principal
// point's shift reads, to first order, as its camera's turn, so freeing both
// would leave them to trade. It explains the corners when each camera's
// residual passes its consistency threshold; a camera whose residual with
// the shift alone (its lens as stored) passes too is not named.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "calib/check/camera_change.h"
#include "calib/core/rig.h"
#include "targets/target.h"

namespace stereorig {

// One camera of the module: its views with the board poses the other
// modules imply, and its consistency threshold (per-axis RMS).
struct ModuleCameraViews {
  int camera = -1;
  std::vector<PosedView> views;
  double threshold_px = 0;
};

struct ModuleShift {
  bool explains = false;      // every camera's residual within its threshold
  bool shift_needed = false;  // the lenses alone (no shift) leave some camera over its threshold
  Eigen::Vector3d shift_mm = Eigen::Vector3d::Zero();  // the module's cameras' centres, in the reference frame
  // Each camera whose lens the shift alone does not explain: the fit's lens
  // estimate and residual (lens_rms_px), and a turn of its own about its
  // centre fitted instead (moved_rms_px, turned_deg; shifted 0: its shift
  // is the module's): kind kMovedOrLens where that turn explains it too (a
  // principal point's shift reads, to first order, as a turn), else kLens.
  std::vector<CameraChange> lenses;
};

ModuleShift ExplainModuleShift(const Rig& rig, const Target& target, const std::vector<ModuleCameraViews>& cameras);

}  // namespace stereorig
