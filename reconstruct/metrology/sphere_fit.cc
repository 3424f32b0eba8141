#include "reconstruct/metrology/sphere_fit.h"

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "calib/core/input_error.h"

namespace stereorig {

void SphereFitOptions::Check() const {
  if (ransac_iterations < 1) throw InputError("sphere fit", "ransac_iterations must be >= 1");
  if (!(inlier_threshold_mm > 0)) throw InputError("sphere fit", "inlier_threshold_mm must be positive");
  if (expected_radius_mm < 0 || radius_tolerance_mm < 0) throw InputError("sphere fit", "radius must not be negative");
  if (max_iterations < 1) throw InputError("sphere fit", "max_iterations must be >= 1");
}

namespace {

// The sphere through 4 points: |p|^2 + D.p + E = 0 is linear in (D, E).
bool SphereThrough4(const Eigen::Vector3d* p, Eigen::Vector3d* c, double* r) {
  Eigen::Matrix4d a;
  Eigen::Vector4d b;
  for (int i = 0; i < 4; ++i) {
    a.row(i) << p[i].x(), p[i].y(), p[i].z(), 1.0;
    b[i] = -p[i].squaredNorm();
  }
  Eigen::FullPivLU<Eigen::Matrix4d> lu(a);
  if (!lu.isInvertible() || std::abs(lu.determinant()) < 1e-9) return false;
  const Eigen::Vector4d x = lu.solve(b);
  *c = -0.5 * x.head<3>();
  const double r2 = c->squaredNorm() - x[3];
  if (!(r2 > 0)) return false;
  *r = std::sqrt(r2);
  return true;
}

}  // namespace

SphereFit RefineSphere(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                       const Eigen::Vector3d& initial_center_mm, double initial_radius_mm, int max_iterations) {
  SphereFit fit;
  fit.inliers = indices;
  if (indices.size() < 4) {
    fit.message = "fewer than 4 points";
    return fit;
  }
  // Parameters (cx, cy, cz, r); residual e_i = |p_i - c| - r;
  // de/dc = -(p - c)/|p - c|, de/dr = -1.
  Eigen::Vector4d x(initial_center_mm.x(), initial_center_mm.y(), initial_center_mm.z(), initial_radius_mm);
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
    Eigen::Vector4d jte = Eigen::Vector4d::Zero();
    for (int i : indices) {
      const Eigen::Vector3d d = points[i] - x.head<3>();
      const double n = d.norm();
      if (n < 1e-12) continue;
      Eigen::Vector4d j;
      j << -d / n, -1.0;
      jtj += j * j.transpose();
      jte += j * (n - x[3]);
    }
    const Eigen::Vector4d step = jtj.ldlt().solve(-jte);
    if (!step.allFinite()) {
      fit.message = "degenerate geometry (points do not constrain a sphere)";
      return fit;
    }
    x += step;
    if (step.norm() < 1e-12 * (1.0 + x.norm())) break;
  }
  fit.center_mm = x.head<3>();
  fit.radius_mm = x[3];
  double ss = 0;
  for (int i : indices) {
    const double e = (points[i] - fit.center_mm).norm() - fit.radius_mm;
    fit.residuals_mm.push_back(e);
    ss += e * e;
  }
  fit.rms_mm = std::sqrt(ss / indices.size());
  fit.ok = std::isfinite(fit.radius_mm) && fit.radius_mm > 0;
  if (!fit.ok) fit.message = "did not converge to a sphere";
  return fit;
}

SphereFit FitSphereRobust(const std::vector<Eigen::Vector3d>& points, const SphereFitOptions& o) {
  o.Check();
  SphereFit best;
  const int n = static_cast<int>(points.size());
  if (n < 4) {
    best.message = "fewer than 4 points";
    return best;
  }
  std::mt19937 rng(o.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best_count = 0;
  Eigen::Vector3d best_c;
  double best_r = 0;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    Eigen::Vector3d s[4];
    int idx[4];
    for (int k = 0; k < 4; ++k) {
      idx[k] = pick(rng);
      s[k] = points[idx[k]];
    }
    if (idx[0] == idx[1] || idx[0] == idx[2] || idx[0] == idx[3] || idx[1] == idx[2] || idx[1] == idx[3] ||
        idx[2] == idx[3])
      continue;
    Eigen::Vector3d c;
    double r;
    if (!SphereThrough4(s, &c, &r)) continue;
    if (o.expected_radius_mm > 0 && std::abs(r - o.expected_radius_mm) > o.radius_tolerance_mm) continue;
    int count = 0;
    for (const auto& p : points) count += std::abs((p - c).norm() - r) < o.inlier_threshold_mm;
    if (count > best_count) {
      best_count = count;
      best_c = c;
      best_r = r;
    }
  }
  if (best_count < 4) {
    best.message = "RANSAC found no sphere with 4 or more inliers";
    return best;
  }
  // Refine on the consensus set, then recompute the set once with the better
  // sphere (a 4-point hypothesis is noisy) and refine again.
  std::vector<int> inliers;
  for (int i = 0; i < n; ++i)
    if (std::abs((points[i] - best_c).norm() - best_r) < o.inlier_threshold_mm) inliers.push_back(i);
  SphereFit fit = RefineSphere(points, inliers, best_c, best_r, o.max_iterations);
  if (!fit.ok) return fit;
  inliers.clear();
  for (int i = 0; i < n; ++i)
    if (std::abs((points[i] - fit.center_mm).norm() - fit.radius_mm) < o.inlier_threshold_mm) inliers.push_back(i);
  return RefineSphere(points, inliers, fit.center_mm, fit.radius_mm, o.max_iterations);
}

}  // namespace stereorig
