#include "reconstruct/metrology/sphere_uncertainty.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

constexpr double kCapQuantile = 0.99;

double CapHalfAngleDeg(const std::vector<Eigen::Vector3d>& points, const SphereFit& fit) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i : fit.inliers) sum += (points[i] - fit.center_mm).normalized();
  // Points all round the sphere have no mean direction: any axis sees 180.
  if (sum.norm() < 1e-9 * fit.inliers.size()) return 180.0;
  const Eigen::Vector3d axis = sum.normalized();
  std::vector<double> angles_deg;
  angles_deg.reserve(fit.inliers.size());
  for (int i : fit.inliers) {
    const double c = std::clamp((points[i] - fit.center_mm).normalized().dot(axis), -1.0, 1.0);
    angles_deg.push_back(std::acos(c) * 180.0 / M_PI);
  }
  const size_t k = std::min(angles_deg.size() - 1, static_cast<size_t>(std::floor(kCapQuantile * angles_deg.size())));
  std::nth_element(angles_deg.begin(), angles_deg.begin() + k, angles_deg.end());
  return angles_deg[k];
}

}  // namespace

SphereFitUncertainty SphereUncertainty(const std::vector<Eigen::Vector3d>& points, const SphereFit& fit) {
  STEREORIG_CHECK(fit.ok && fit.inliers.size() > 4 && fit.residuals_mm.size() == fit.inliers.size());
  SphereFitUncertainty u;
  u.cap_half_angle_deg = CapHalfAngleDeg(points, fit);
  // Parameters (cx, cy, cz, r), residual |p - c| - r: the Jacobian row of
  // RefineSphere, at the solution.
  Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
  double ss_mm2 = 0;
  for (size_t k = 0; k < fit.inliers.size(); ++k) {
    const Eigen::Vector3d d = points[fit.inliers[k]] - fit.center_mm;
    Eigen::Vector4d j;
    j << -d.normalized(), -1.0;
    jtj += j * j.transpose();
    ss_mm2 += fit.residuals_mm[k] * fit.residuals_mm[k];
  }
  const double sigma2_mm2 = ss_mm2 / static_cast<double>(fit.inliers.size() - 4);
  // A cap too small to pin the parameters (J'J near singular: Eigen's LDLT
  // would solve it as a pseudo-inverse and read an undetermined radius as
  // exact) reads as infinitely uncertain, and so does a variance that is not
  // positive and finite.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(jtj);
  const Eigen::Vector4d values = eigen.eigenvalues();  // increasing
  constexpr double kInfinite = std::numeric_limits<double>::infinity();
  if (!(values(0) > 1e-12 * values(3))) {
    u.diameter_std_mm = kInfinite;
    u.center_covariance_mm2 = Eigen::Vector3d::Constant(kInfinite).asDiagonal();
    return u;
  }
  const Eigen::Matrix4d covariance =
      sigma2_mm2 * eigen.eigenvectors() * values.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  u.diameter_std_mm =
      covariance(3, 3) > 0 && std::isfinite(covariance(3, 3)) ? 2 * std::sqrt(covariance(3, 3)) : kInfinite;
  u.center_covariance_mm2 = covariance.topLeftCorner<3, 3>();
  return u;
}

}  // namespace stereorig
