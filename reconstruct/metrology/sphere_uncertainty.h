// How well a least-squares sphere is determined by the points it was fitted
// to. A small cap pins the radius badly: over a cap of half-angle theta the
// radius is read from the cap's sagitta, R (1 - cos theta) ~ R theta^2 / 2, so
// its standard uncertainty grows like 1 / theta^2 (measured in
// sphere_uncertainty_test.cc). VDI/VDE 2634-2's P_S of such a cap is
// the noise of the fit, not the system's size error; verify reports these
// numbers and refuses a position whose figure they leave undetermined.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "reconstruct/metrology/sphere_fit.h"

namespace stereorig {

struct SphereFitUncertainty {
  // The half-angle of the cone about the points' mean direction (from the
  // fitted centre) that holds 99% of them, degrees: 90 for a hemisphere, near
  // 180 for a sphere seen from both sides, and also for two small opposite
  // caps (it is the extent about one axis, not the share of the sphere
  // covered: the uncertainties below are what says how well the points pin
  // the sphere). The 99% keeps a few strays from setting it (above ~100
  // points; with fewer, it is the largest angle).
  double cap_half_angle_deg = 0;
  // Standard uncertainties (k = 1) from the Gauss-Newton fit's covariance,
  // sigma^2 (J^T J)^-1, with sigma^2 = sum e^2 / (n - 4) from the residuals
  // themselves. They count the points as independent: noise correlated over
  // neighbouring points (a matching window) makes the real scatter larger.
  double diameter_std_mm = 0;
  Eigen::Matrix3d center_covariance_mm2 = Eigen::Matrix3d::Zero();
};

// fit: a converged fit of `points` (fit.inliers index them; fit.residuals_mm
// parallel). At least 5 inliers.
SphereFitUncertainty SphereUncertainty(const std::vector<Eigen::Vector3d>& points, const SphereFit& fit);

}  // namespace stereorig
