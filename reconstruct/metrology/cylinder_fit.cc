#include "reconstruct/metrology/cylinder_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "calib/core/input_error.h"
#include "reconstruct/metrology/least_squares.h"
#include "reconstruct/metrology/ransac.h"

namespace stereorig {

void CylinderFitOptions::Check() const {
  if (ransac_iterations < 1) throw InputError("cylinder fit", "ransac_iterations must be >= 1");
  if (max_scoring_points < 10) throw InputError("cylinder fit", "max_scoring_points must be >= 10");
  if (!(inlier_threshold_mm > 0)) throw InputError("cylinder fit", "inlier_threshold_mm must be positive");
  if (!(max_normal_angle_deg > 0 && max_normal_angle_deg <= 90))
    throw InputError("cylinder fit", "max_normal_angle_deg must be in (0, 90]");
  if (max_radius_mm < 0) throw InputError("cylinder fit", "max_radius_mm must not be negative");
  if (!(extent_quantile >= 0 && extent_quantile < 0.5)) throw InputError("cylinder fit", "extent_quantile in [0, 0.5)");
}

double CylinderFit::Distance(const Eigen::Vector3d& p) const {
  return (p - axis_point_mm).cross(axis_direction).norm() - radius_mm;
}

namespace {

struct Axis {
  Eigen::Vector3d point, direction;
  double radius = 0;
};

// The cylinder through two oriented points: the axis is along n1 x n2; in
// the plane normal to it, the two normal lines meet on the axis.
bool CylinderFrom2(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1, const Eigen::Vector3d& p2,
                   const Eigen::Vector3d& n2, Axis* out) {
  Eigen::Vector3d d = n1.cross(n2);
  if (d.norm() < 0.1) return false;  // normals within ~6 degrees: the axis is ill-defined
  d.normalize();
  auto flat = [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(v - v.dot(d) * d); };
  const Eigen::Vector3d m1 = flat(n1).normalized(), m2 = flat(n2).normalized();
  Eigen::Matrix<double, 3, 2> a;
  a << m1, -m2;
  const Eigen::Vector2d t = a.colPivHouseholderQr().solve(flat(p2) - flat(p1));
  const Eigen::Vector3d c = 0.5 * (flat(p1) + t[0] * m1 + flat(p2) + t[1] * m2);
  const double r1 = (flat(p1) - c).norm(), r2 = (flat(p2) - c).norm();
  if (!(std::abs(r1 - r2) < 0.05 * (r1 + r2))) return false;
  *out = {c, d, 0.5 * (r1 + r2)};
  return std::isfinite(out->radius);
}

double AxisDistance(const Axis& a, const Eigen::Vector3d& p) { return (p - a.point).cross(a.direction).norm(); }

// LM on (axis point offset 2, direction tilt 2, radius) about `a`.
Axis Refine(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& idx, const Axis& a, bool* converged) {
  Eigen::Vector3d e1 = a.direction.unitOrthogonal(), e2 = a.direction.cross(e1);
  auto unpack = [&](const Eigen::VectorXd& x) {
    return Axis{a.point + x[0] * e1 + x[1] * e2, (a.direction + x[2] * e1 + x[3] * e2).normalized(), x[4]};
  };
  const ResidualFunction f = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r) {
    const Axis c = unpack(x);
    for (size_t k = 0; k < idx.size(); ++k) (*r)[k] = AxisDistance(c, pts[idx[k]]) - c.radius;
  };
  Eigen::VectorXd x(5);
  x << 0, 0, 0, 0, a.radius;
  *converged = MinimiseSumOfSquares(static_cast<int>(idx.size()), f, &x).converged;
  return unpack(x);
}

}  // namespace

CylinderFit FitCylinderRobust(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                              const CylinderFitOptions& o) {
  o.Check();
  CylinderFit fit;
  const int n = static_cast<int>(points.size());
  if (n < 10) {
    fit.message = "fewer than 10 points";
    return fit;
  }
  if (normals.size() != points.size()) {
    fit.message = "the cylinder fit needs a normal per point";
    return fit;
  }
  const double cos_normal = std::cos(o.max_normal_angle_deg * M_PI / 180);
  auto consistent = [&](const Axis& a, int i) {
    const Eigen::Vector3d v = points[i] - a.point;
    const Eigen::Vector3d radial = v - v.dot(a.direction) * a.direction;
    return std::abs(AxisDistance(a, points[i]) - a.radius) < o.inlier_threshold_mm &&
           std::abs(radial.normalized().dot(normals[i])) > cos_normal;
  };
  std::mt19937 rng(o.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  const std::function<bool(Axis*)> draw = [&](Axis* a) {
    const int i = pick(rng), j = pick(rng);
    return i != j && CylinderFrom2(points[i], normals[i], points[j], normals[j], a) &&
           !(o.max_radius_mm > 0 && a->radius > o.max_radius_mm);
  };
  const std::function<bool(const Axis&, int)> agrees = consistent;
  Axis best;
  if (RansacBest(o.ransac_iterations, n, o.max_scoring_points, draw, agrees, &best) < 10) {
    fit.message = "RANSAC found no cylinder with 10 or more inliers";
    return fit;
  }
  // Refine on the consensus set, re-segment with the better cylinder (by
  // distance alone), refine again.
  std::vector<int> inliers = Inliers(n, best, agrees);
  bool converged = false;
  Axis a = Refine(points, inliers, best, &converged);
  for (int round = 0; round < 2 && converged; ++round) {
    inliers = Inliers<Axis>(n, a, [&](const Axis& c, int k) {
      return std::abs(AxisDistance(c, points[k]) - c.radius) < o.inlier_threshold_mm;
    });
    if (inliers.size() < 10) break;
    a = Refine(points, inliers, a, &converged);
  }
  if (!converged || inliers.size() < 10 || !(a.radius > 0)) {
    fit.message = "the least-squares refinement did not converge";
    return fit;
  }
  // The extent: robust quantiles of the inliers along the axis.
  std::vector<double> t;
  for (int k : inliers) t.push_back((points[k] - a.point).dot(a.direction));
  std::sort(t.begin(), t.end());
  const size_t lo = static_cast<size_t>(o.extent_quantile * (t.size() - 1));
  const double t0 = t[lo], t1 = t[t.size() - 1 - lo];
  fit.axis_point_mm = a.point + 0.5 * (t0 + t1) * a.direction;
  fit.axis_direction = a.direction;
  fit.radius_mm = a.radius;
  fit.length_mm = t1 - t0;
  fit.inliers = inliers;
  double ss = 0;
  for (int k : inliers) {
    fit.residuals_mm.push_back(fit.Distance(points[k]));
    ss += fit.residuals_mm.back() * fit.residuals_mm.back();
  }
  fit.rms_mm = std::sqrt(ss / inliers.size());
  fit.ok = true;
  return fit;
}

}  // namespace stereorig
