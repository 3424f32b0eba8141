// Every camera's lens changed alike: a change the cameras share (a
// temperature change scaling every focal length, every principal point
// drifting alike) leaves no camera unchanged to read the others against.
// Each camera's figure fails through the others' board poses, and naming
// the cameras one by one named the worse of each module, "neither a new
// pose nor a new lens alone explains", as if the others had not changed.
//
// One change shared by every camera is fitted instead, with one board pose
// per capture from every camera: fx and fy by one factor (1 + focal_percent
// / 100), (cx, cy) moved by principal_point_px, as the per-camera lens fit
// (camera_change.h) frees, but alike for all. The caller judges whether it
// explains the night (every camera's figures within their thresholds with
// the rig so changed).
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "calib/observations.h"
#include "targets/target.h"

namespace stereorig {

struct SharedLensChange {
  bool fitted = false;  // false: too few corners, or the solve failed
  double focal_percent = 0;
  Eigen::Vector2d principal_point_px = Eigen::Vector2d::Zero();
  int corners = 0;
  // The turn a principal point's shift reads as, to first order (d / f rad,
  // f the cameras' mean fx): every camera turned alike by it is the same
  // night to the check (camera_change.h).
  double turn_equivalent_deg = 0;
  // "every camera's lens changed alike: focal length +0.100 %, principal
  // point +0.00, +0.00 px"; where the principal point moved by enough to
  // read as a turn at the precision printed (0.001 deg), ", or every camera
  // turned alike by 0.028 deg, as which its shift reads".
  std::string Describe() const;
};

// The change shared by every camera that best fits the captures
// (`by_capture`: capture -> its views), each capture's board pose free and
// seeded from `seed` (capture -> ref_from_front; captures without one are
// left out).
SharedLensChange FitSharedLensChange(const Rig& rig, const Target& target,
                                     const std::map<int, std::vector<const BoardObservation*>>& by_capture,
                                     const std::map<int, Pose>& seed);

// `rig` with every camera's lens changed so.
Rig WithSharedLensChange(const Rig& rig, const SharedLensChange& change);

}  // namespace stereorig
