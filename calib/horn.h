// Horn's closed-form absolute orientation with unit quaternions (B. K. P. Horn,
// "Closed-form solution of absolute orientation using unit quaternions",
// JOSA A 4(4), 1987), written here.
//
// Given the same points measured in two frames, a_i ~ a_from_b * b_i, find
// the rigid a_from_b (no scale) minimising sum_i w_i |a_i - (R b_i + t)|^2.
// The rotation is the unit quaternion that maximises q' N q, i.e. the
// eigenvector of the largest eigenvalue of Horn's symmetric 4x4 matrix N built
// from the cross-covariance of the centred point sets; the translation then
// maps the weighted centroid of b onto that of a.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/core/pose.h"

namespace stereorig {

struct HornResult {
  bool ok = false;  // false: fewer than 3 points, or they are (nearly) collinear
  std::string message;
  Pose a_from_b;
  double rms_mm = 0.0;  // RMS of |a_i - a_from_b * b_i|
};

// points_a, points_b: (N,) corresponding points. weights: (N,) or empty (all 1).
HornResult HornAbsoluteOrientation(const std::vector<Eigen::Vector3d>& points_a,
                                   const std::vector<Eigen::Vector3d>& points_b,
                                   const std::vector<double>& weights = {});

}  // namespace stereorig
