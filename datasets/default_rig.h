// The embedded default rig: the seed paper's experimental setup
// (../shared/BRIEF.md, "The default rig").
//
// Two modules face each other across the object, which sits near the world
// origin: module 0 looks along world +z, module 1 along world -z, each at a
// 200 mm working distance. Each module: two 752x582 cameras, 8.3 um pixels,
// f = 8.5 mm (fx = fy ~ 1024 px), mild OPENCV8 distortion, a 90 mm baseline
// and 6 degrees of inward verging between the optical axes.
#pragma once

#include "calib/core/rig.h"

namespace stereorig {

struct DefaultRigGeometry {
  double baseline_mm = 90.0;
  double verging_deg = 6.0;  // angle between the two optical axes
  double working_distance_mm = 200.0;
  double focal_length_mm = 8.5;
  double pixel_pitch_um = 8.3;
  int imager_width_px = 752;
  int imager_height_px = 582;
};

// The true rig, and where it sits in the simulator's world frame.
struct SimulatedRig {
  Rig rig;
  Pose world_from_module0;  // the rig's reference frame is module 0's frame
};

SimulatedRig MakeDefaultRig(const DefaultRigGeometry& geometry = {});

}  // namespace stereorig
