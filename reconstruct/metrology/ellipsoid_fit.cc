#include "reconstruct/metrology/ellipsoid_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <random>

#include "calib/core/input_error.h"
#include "reconstruct/metrology/least_squares.h"
#include "reconstruct/metrology/ransac.h"

namespace stereorig {

void EllipsoidFitOptions::Check() const {
  if (ransac_iterations < 1) throw InputError("ellipsoid fit", "ransac_iterations must be >= 1");
  if (max_scoring_points < 10) throw InputError("ellipsoid fit", "max_scoring_points must be >= 10");
  if (sample_size < 9) throw InputError("ellipsoid fit", "sample_size must be >= 9");
  if (!(inlier_threshold_mm > 0)) throw InputError("ellipsoid fit", "inlier_threshold_mm must be positive");
  if (max_semi_axis_mm < 0) throw InputError("ellipsoid fit", "max_semi_axis_mm must not be negative");
}

namespace {

struct Ellipsoid {
  Eigen::Vector3d c;
  Eigen::Matrix3d r;  // frame_from_ellipsoid
  Eigen::Vector3d a;  // semi-axes
};

// Sampson distance: g(u) = sum u_i^2/a_i^2 - 1 over |grad g|, u in the
// ellipsoid's frame. Exact on the surface, first-order near it.
double SampsonDistance(const Ellipsoid& e, const Eigen::Vector3d& p) {
  const Eigen::Vector3d u = e.r.transpose() * (p - e.c);
  const Eigen::Vector3d w = u.cwiseQuotient(e.a.cwiseProduct(e.a));
  const double g = u.dot(w) - 1, grad = 2 * w.norm();
  return grad > 0 ? g / grad : -e.a.minCoeff();
}

// The algebraic quadric x'Ax + b'x + c = 0 through `idx` (least squares,
// |coefficients| = 1), on coordinates centred on `origin` and divided by
// `scale`; converted to an ellipsoid if it is one.
bool AlgebraicEllipsoid(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& idx,
                        const Eigen::Vector3d& origin, double scale, Ellipsoid* out) {
  Eigen::MatrixXd d(idx.size(), 10);
  for (size_t k = 0; k < idx.size(); ++k) {
    const Eigen::Vector3d q = (pts[idx[k]] - origin) / scale;
    d.row(k) << q.x() * q.x(), q.y() * q.y(), q.z() * q.z(), 2 * q.x() * q.y(), 2 * q.x() * q.z(), 2 * q.y() * q.z(),
        q.x(), q.y(), q.z(), 1;
  }
  Eigen::VectorXd v;
  if (idx.size() >= 10) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(d.transpose() * d);
    v = es.eigenvectors().col(0);
  } else {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(d, Eigen::ComputeFullV);
    v = svd.matrixV().col(9);
  }
  Eigen::Matrix3d a;
  a << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
  const Eigen::Vector3d b(v[6], v[7], v[8]);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(a);
  if (!lu.isInvertible()) return false;
  const Eigen::Vector3d c = -0.5 * lu.solve(b);
  const double k = c.dot(a * c) - v[9];  // (q - c)' A (q - c) = k
  if (!(std::abs(k) > 0)) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(a / k);
  if (!(es.eigenvalues().minCoeff() > 0)) return false;  // not an ellipsoid
  out->c = origin + scale * c;
  out->r = es.eigenvectors();
  if (out->r.determinant() < 0) out->r.col(2) = -out->r.col(2);
  out->a = scale * es.eigenvalues().cwiseSqrt().cwiseInverse();
  return out->a.allFinite();
}

// LM on (centre 3, rotation vector 3 about the start's frame, log semi-axes 3).
Ellipsoid Refine(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& idx, const Ellipsoid& e0,
                 bool* converged) {
  auto unpack = [&](const Eigen::VectorXd& x) {
    const Eigen::Vector3d w(x[3], x[4], x[5]);
    const double angle = w.norm();
    const Eigen::Matrix3d dr =
        angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
    return Ellipsoid{e0.c + Eigen::Vector3d(x[0], x[1], x[2]), e0.r * dr,
                     Eigen::Vector3d(std::exp(x[6]), std::exp(x[7]), std::exp(x[8]))};
  };
  const ResidualFunction f = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r) {
    const Ellipsoid e = unpack(x);
    for (size_t k = 0; k < idx.size(); ++k) (*r)[k] = SampsonDistance(e, pts[idx[k]]);
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(9);
  x.tail<3>() = e0.a.array().log();
  *converged = MinimiseSumOfSquares(static_cast<int>(idx.size()), f, &x).converged;
  return unpack(x);
}

}  // namespace

double EllipsoidFit::Distance(const Eigen::Vector3d& p) const {
  return SampsonDistance({center_mm, frame_from_ellipsoid, semi_axes_mm}, p);
}

Eigen::Vector3d EllipsoidFit::SurfacePoint(double theta, double phi, Eigen::Vector3d* normal) const {
  const Eigen::Vector3d s(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  const Eigen::Vector3d u = semi_axes_mm.cwiseProduct(s);
  if (normal) *normal = (frame_from_ellipsoid * s.cwiseQuotient(semi_axes_mm)).normalized();
  return center_mm + frame_from_ellipsoid * u;
}

EllipsoidFit FitEllipsoidRobust(const std::vector<Eigen::Vector3d>& points, const EllipsoidFitOptions& o) {
  o.Check();
  EllipsoidFit fit;
  const int n = static_cast<int>(points.size());
  if (n < 20) {
    fit.message = "fewer than 20 points";
    return fit;
  }
  // Normalisation for the algebraic fits: centroid and RMS spread.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const auto& p : points) origin += p;
  origin /= n;
  double scale = 0;
  for (const auto& p : points) scale += (p - origin).squaredNorm();
  scale = std::sqrt(scale / n);
  if (!(scale > 0)) {
    fit.message = "all points coincide";
    return fit;
  }
  const std::function<bool(const Ellipsoid&, int)> in_band = [&](const Ellipsoid& e, int i) {
    return std::abs(SampsonDistance(e, points[i])) < o.inlier_threshold_mm;
  };
  std::mt19937 rng(o.seed);
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  const std::function<bool(Ellipsoid*)> draw = [&](Ellipsoid* e) {
    std::vector<int> sample;
    std::sample(all.begin(), all.end(), std::back_inserter(sample), o.sample_size, rng);
    return AlgebraicEllipsoid(points, sample, origin, scale, e) &&
           !(o.max_semi_axis_mm > 0 && e->a.maxCoeff() > o.max_semi_axis_mm);
  };
  Ellipsoid best;
  if (RansacBest(o.ransac_iterations, n, o.max_scoring_points, draw, in_band, &best) < 20) {
    fit.message = "RANSAC found no ellipsoid with 20 or more inliers";
    return fit;
  }
  // Refine: algebraic on the consensus set, then geometric, re-segmented.
  std::vector<int> inliers = Inliers(n, best, in_band);
  Ellipsoid e = best;
  AlgebraicEllipsoid(points, inliers, origin, scale, &e);
  bool converged = false;
  for (int round = 0; round < 3; ++round) {
    e = Refine(points, inliers, e, &converged);
    if (!converged) break;
    inliers = Inliers(n, e, in_band);
    if (inliers.size() < 20) break;
  }
  if (!converged || inliers.size() < 20) {
    fit.message = "the least-squares refinement did not converge";
    return fit;
  }
  fit.center_mm = e.c;
  fit.frame_from_ellipsoid = e.r;
  fit.semi_axes_mm = e.a;
  fit.inliers = inliers;
  double ss = 0;
  for (int k : inliers) {
    fit.residuals_mm.push_back(SampsonDistance(e, points[k]));
    ss += fit.residuals_mm.back() * fit.residuals_mm.back();
  }
  fit.rms_mm = std::sqrt(ss / inliers.size());
  fit.ok = true;
  return fit;
}

}  // namespace stereorig
