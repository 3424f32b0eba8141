#include "reconstruct/metrology/plane_fit.h"

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "calib/core/input_error.h"

namespace stereorig {

void PlaneFitOptions::Check() const {
  if (ransac_iterations < 1) throw InputError("plane fit", "ransac_iterations must be >= 1");
  if (!(inlier_threshold_mm > 0)) throw InputError("plane fit", "inlier_threshold_mm must be positive");
}

PlaneFit FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices) {
  PlaneFit fit;
  fit.inliers = indices;
  if (indices.size() < 3) {
    fit.message = "fewer than 3 points";
    return fit;
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : indices) mean += points[i];
  mean /= indices.size();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i : indices) scatter += (points[i] - mean) * (points[i] - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(scatter);
  if (es.info() != Eigen::Success || es.eigenvalues()[1] <= 0) {
    fit.message = "degenerate geometry (points on a line)";
    return fit;
  }
  fit.normal = es.eigenvectors().col(0);  // smallest eigenvalue first
  fit.offset_mm = fit.normal.dot(mean);
  double ss = 0;
  for (int i : indices) {
    const double e = fit.normal.dot(points[i]) - fit.offset_mm;
    fit.residuals_mm.push_back(e);
    ss += e * e;
  }
  fit.rms_mm = std::sqrt(ss / indices.size());
  fit.ok = true;
  return fit;
}

PlaneFit FitPlaneRobust(const std::vector<Eigen::Vector3d>& points, const PlaneFitOptions& o) {
  o.Check();
  const int n = static_cast<int>(points.size());
  PlaneFit none;
  if (n < 3) {
    none.message = "fewer than 3 points";
    return none;
  }
  std::mt19937 rng(o.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best_count = 0;
  Eigen::Vector3d best_n;
  double best_d = 0;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    const Eigen::Vector3d a = points[pick(rng)], b = points[pick(rng)], c = points[pick(rng)];
    Eigen::Vector3d nrm = (b - a).cross(c - a);
    if (nrm.norm() < 1e-9) continue;
    nrm.normalize();
    const double d = nrm.dot(a);
    int count = 0;
    for (const auto& p : points) count += std::abs(nrm.dot(p) - d) < o.inlier_threshold_mm;
    if (count > best_count) {
      best_count = count;
      best_n = nrm;
      best_d = d;
    }
  }
  if (best_count < 3) {
    none.message = "RANSAC found no plane";
    return none;
  }
  std::vector<int> inliers;
  for (int i = 0; i < n; ++i)
    if (std::abs(best_n.dot(points[i]) - best_d) < o.inlier_threshold_mm) inliers.push_back(i);
  PlaneFit fit = FitPlaneLeastSquares(points, inliers);
  if (!fit.ok) return fit;
  inliers.clear();
  for (int i = 0; i < n; ++i)
    if (std::abs(fit.normal.dot(points[i]) - fit.offset_mm) < o.inlier_threshold_mm) inliers.push_back(i);
  return FitPlaneLeastSquares(points, inliers);
}

}  // namespace stereorig
