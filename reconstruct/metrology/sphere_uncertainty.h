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
  // themselves, times noise_variance_inflation below.
  double diameter_std_mm = 0;
  Eigen::Matrix3d center_covariance_mm2 = Eigen::Matrix3d::Zero();
  // How many times larger the parameters' variances are than independent
  // points would give: a reconstruction's noise is shared by neighbouring
  // points (a matching window's footprint: the demo's residuals correlate
  // 0.87 at 0.2-0.5 mm, 0.26 at 1-2 mm, none beyond 2 mm), so a cloud of n
  // points holds about n / inflation independent ones. Measured from the
  // residuals (NoiseVarianceInflation); 1 for independent noise. Without it
  // the demo's 18-20 degree caps fitted their diameters to a stated +-0.1 mm
  // while scattering +-1 mm, and read a false FAIL "beyond doubt".
  double noise_variance_inflation = 1;
};

// The residuals' neighbours within this distance, mm, are weighted (1 -
// d / radius) in NoiseVarianceInflation (Bartlett's kernel): over the
// demo's caps of 20 to 45 degrees the inflated u predicts the diameters'
// scatter to 0.9-1.24x (docs/verify-and-check.md); 4 or 6 mm, or a flat
// weight, predicted it worse.
inline constexpr double kNoiseCorrelationRadiusMm = 3.0;

// The variance inflation of a least-squares fit whose residuals
// (residuals_mm) are correlated between neighbouring points, each at its
// place on the fitted surface (surface_mm, parallel: the point moved onto
// it, so that a residual does not move its neighbours): 1 + sum_{i != j}
// w_ij e_i e_j / sum e_i^2, w_ij = 1 - d_ij / radius_mm for points closer
// than radius_mm (the fit's Jacobian changes little over that distance, so
// the covariance scales by it), less twice its own standard error under
// independent noise (so that independent noise reads 1, not the estimate's
// scatter about it), and at least 1. A pattern on the surface (a patch a
// grid period off, a form error) is not noise and is taken out of the sum:
// where the products of pairs radius_mm to 2 radius_mm apart hold one
// (their mean correlation over 0.05), a line through them against distance,
// extrapolated over the near pairs, is its part there (the .cc says why).
double NoiseVarianceInflation(const std::vector<Eigen::Vector3d>& surface_mm, const std::vector<double>& residuals_mm,
                              double radius_mm = kNoiseCorrelationRadiusMm);

// fit: a converged fit of `points` (fit.inliers index them; fit.residuals_mm
// parallel). At least 5 inliers.
SphereFitUncertainty SphereUncertainty(const std::vector<Eigen::Vector3d>& points, const SphereFit& fit);

}  // namespace stereorig
