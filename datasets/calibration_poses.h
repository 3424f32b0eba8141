// Where the simulated operator holds the target: N poses spread over the
// measurement volume, tilted up to +-tilt_max_deg, so that the corners reach
// every camera's image corners. A pose is redrawn until every camera sees at
// least min_corners_per_camera corners (mrcal needs every board pose observed).
#pragma once

#include <cstdint>
#include <vector>

#include "calib/core/camera.h"
#include "calib/core/pose.h"
#include "datasets/sim_spec.h"
#include "datasets/target_render.h"

namespace stereorig {

// world_from_front per capture. The board's centre walks a jittered 3x3 grid
// over the volume's x-y extent (so the corners fill each image), z uniform.
std::vector<Pose> MakeCalibrationPoses(const CalibrationSpec& spec, const PhysicalBoard& board,
                                       const std::vector<Camera>& cameras, const std::vector<Pose>& world_from_camera,
                                       uint64_t seed);

}  // namespace stereorig
