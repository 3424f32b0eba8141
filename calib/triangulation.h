// Triangulation of a pixel pair seen by a module's two cameras.
#pragma once

#include <Eigen/Core>

#include "calib/core/camera.h"
#include "calib/core/pose.h"

namespace stereorig {

// The point (mm, left = module frame) that the left camera sees at `q_left` and
// the right camera at `q_right`: Lee & Civera's Mid2 method (mrcal's
// implementation) on the unprojected rays. Returns false if a pixel does not
// unproject or the rays diverge.
bool TriangulatePair(const Camera& left, const Camera& right, const Pose& right_from_left,
                     const Eigen::Vector2d& q_left, const Eigen::Vector2d& q_right, Eigen::Vector3d* p_left);

}  // namespace stereorig
