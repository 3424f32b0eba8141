#include "reconstruct/score.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "reconstruct/kd_tree.h"

namespace stereorig {
namespace {

// Pairs whose nearest truth sample is farther are left out of the alignment.
constexpr double kMaxPairDistanceMm = 2.0;
// Points whose nearest truth sample is farther are scored by that distance,
// not by the local plane's (ScoreAligned).
constexpr double kPlaneReachMm = 1.0;

// Plane through the k nearest truth samples of q: (centroid, unit normal).
bool LocalPlane(const KdTree3& tree, const Eigen::Vector3d& q, Eigen::Vector3d* c, Eigen::Vector3d* n,
                double* nearest) {
  std::vector<int> idx;
  std::vector<double> d2;
  tree.Knn(q, 8, &idx, &d2);
  if (idx.size() < 4) return false;
  *nearest = std::sqrt(d2[0]);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : idx) mean += tree.points()[i];
  mean /= double(idx.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : idx) cov += (tree.points()[i] - mean) * (tree.points()[i] - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  *c = mean;
  *n = es.eigenvectors().col(0);
  return true;
}

ErrorFigures Figures(std::vector<double> e) {
  ErrorFigures f;
  f.points = int(e.size());
  if (e.empty()) return f;
  double s = 0, s2 = 0, sa = 0;
  for (double v : e) s += v, s2 += v * v, sa += std::abs(v);
  f.mean_mm = s / e.size();
  f.mean_abs_mm = sa / e.size();
  f.rms_mm = std::sqrt(s2 / e.size());
  f.std_mm = std::sqrt(std::max(0.0, s2 / e.size() - f.mean_mm * f.mean_mm));
  for (double& v : e) v = std::abs(v);
  const size_t k = std::min(e.size() - 1, size_t(0.95 * e.size()));
  std::nth_element(e.begin(), e.begin() + k, e.end());
  f.p95_abs_mm = e[k];
  f.max_abs_mm = *std::max_element(e.begin(), e.end());
  f.within_0_5_mm = double(std::count_if(e.begin(), e.end(), [](double v) { return v <= 0.5; })) / e.size();
  return f;
}

// The figures of `cloud` moved by `truth_from_cloud`, against the truth
// samples in `tree`.
CloudScore ScoreAligned(const PointCloud& cloud, const KdTree3& tree, const Pose& truth_from_cloud, int num_modules);

}  // namespace

CloudScore ScoreAgainstTruth(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& truth, int num_modules) {
  const KdTree3 tree(truth);
  // ICP, point-to-plane, on up to 20k measured points.
  std::vector<Eigen::Vector3d> sample;
  std::vector<size_t> measured;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (cloud.module[i] != kFilledModule) measured.push_back(i);
  const size_t step = std::max<size_t>(1, measured.size() / 20000);
  for (size_t i = 0; i < measured.size(); i += step) sample.push_back(cloud.xyz_mm[measured[i]].cast<double>());
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  // Robust, damped Gauss-Newton: pairs whose plane distance exceeds 3x the
  // median are ignored (mismatches), and a small Levenberg term keeps
  // directions the surface cannot fix (a sphere's rotations about its
  // centre) at zero motion instead of drifting. Rotations are taken about
  // the origin, ~200 mm from the object, so that term (1e-6 of the trace,
  // which that lever dominates) also holds directions the surface fixes
  // only weakly near the identity: the motion reported is the smallest that
  // fits, to ~0.02 deg in such directions (score_test.cc measured it on an
  // ellipsoidal cap); the distances change by well under a micrometre.
  // Taken about the sample's centroid instead, with a prior on the whole
  // motion, the sphere's and the ball bar's reported rotations went to
  // 0.3-11 deg (noise drives the directions the 8-sample planes' normals
  // barely fix) for the same figures to 0.02 um (session 17): not taken.
  for (int it = 0; it < 30 && !sample.empty(); ++it) {
    std::vector<Eigen::Matrix<double, 6, 1>> js;
    std::vector<double> rs;
    for (const Eigen::Vector3d& p0 : sample) {
      const Eigen::Vector3d p = r * p0 + t;
      Eigen::Vector3d c, n;
      double nearest;
      if (!LocalPlane(tree, p, &c, &n, &nearest) || nearest > kMaxPairDistanceMm) continue;
      Eigen::Matrix<double, 6, 1> j;
      j << p.cross(n), n;
      js.push_back(j);
      rs.push_back((c - p).dot(n));
    }
    if (js.size() < 6) break;
    std::vector<double> abs_r(rs.size());
    for (size_t i = 0; i < rs.size(); ++i) abs_r[i] = std::abs(rs[i]);
    std::nth_element(abs_r.begin(), abs_r.begin() + abs_r.size() / 2, abs_r.end());
    const double cut = std::max(0.05, 3.0 * abs_r[abs_r.size() / 2]);
    Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    for (size_t i = 0; i < js.size(); ++i) {
      if (std::abs(rs[i]) > cut) continue;
      a += js[i] * js[i].transpose();
      b += js[i] * rs[i];
    }
    a.diagonal().array() += 1e-6 * a.trace() + 1e-9;
    const Eigen::Matrix<double, 6, 1> x = a.ldlt().solve(b);
    if (!x.allFinite()) break;
    const Eigen::Vector3d w = x.head<3>();
    const Eigen::Matrix3d dr =
        w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() : Eigen::Matrix3d::Identity();
    r = dr * r;
    t = dr * t + x.tail<3>();
    if (w.norm() < 1e-9 && x.tail<3>().norm() < 1e-7) break;
  }
  return ScoreAligned(cloud, tree, Pose(r, t), num_modules);
}

CloudScore ScoreUnderAlignment(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& truth,
                               const Pose& truth_from_cloud, int num_modules) {
  return ScoreAligned(cloud, KdTree3(truth), truth_from_cloud, num_modules);
}

namespace {

CloudScore ScoreAligned(const PointCloud& cloud, const KdTree3& tree, const Pose& truth_from_cloud, int num_modules) {
  CloudScore score;
  score.per_module.resize(num_modules);
  score.truth_from_cloud = truth_from_cloud;
  const Eigen::Matrix3d r = truth_from_cloud.rotation();
  const Eigen::Vector3d t = truth_from_cloud.translation_mm();
  std::vector<size_t> measured;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (cloud.module[i] != kFilledModule) measured.push_back(i);
  std::vector<double> all, filled;
  std::vector<std::vector<double>> per(num_modules);
  // Filled points by distance to the nearest measured point (a rigid motion
  // keeps distances: taken in the cloud's frame).
  const double band_edges_mm[] = {0, 5, 15, std::numeric_limits<double>::infinity()};
  std::vector<std::vector<double>> band(std::size(band_edges_mm) - 1);
  std::unique_ptr<KdTree3> measured_tree;
  if (measured.size() < cloud.size() && !measured.empty()) {
    std::vector<Eigen::Vector3d> measured_points;
    for (size_t i : measured) measured_points.push_back(cloud.xyz_mm[i].cast<double>());
    measured_tree = std::make_unique<KdTree3>(std::move(measured_points));
  }
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = r * cloud.xyz_mm[i].cast<double>() + t;
    Eigen::Vector3d c, n;
    double nearest;
    if (!LocalPlane(tree, p, &c, &n, &nearest)) continue;
    // Sign: positive on the side the cloud's normal points to (outwards).
    const double sign = n.dot(r * cloud.normal[i].cast<double>()) >= 0 ? 1.0 : -1.0;
    const double plane_mm = (p - c).dot(n);
    // The plane stands for the surface only near its samples: a gross
    // mismatch beside an edge (a passive cloud's, 50 mm off) projects onto
    // the plane's extension within a few mm. Beyond kPlaneReachMm the nearest
    // sample's distance is the error (the samples <= 0.2 mm apart: within
    // ~0.1 mm of the surface's).
    const double e = sign * (nearest > kPlaneReachMm ? std::copysign(nearest, plane_mm) : plane_mm);
    if (cloud.module[i] == kFilledModule) {
      filled.push_back(e);
      const double d = measured_tree ? measured_tree->NearestDistance(cloud.xyz_mm[i].cast<double>())
                                     : std::numeric_limits<double>::infinity();
      for (size_t b = 0; b < band.size(); ++b)
        if (d >= band_edges_mm[b] && d < band_edges_mm[b + 1]) band[b].push_back(e);
    } else {
      all.push_back(e);
      if (cloud.module[i] < num_modules) per[cloud.module[i]].push_back(e);
    }
  }
  score.all = Figures(std::move(all));
  score.filled = Figures(std::move(filled));
  for (size_t b = 0; b < band.size(); ++b)
    score.filled_by_distance.push_back({band_edges_mm[b], band_edges_mm[b + 1], Figures(std::move(band[b]))});
  for (int m = 0; m < num_modules; ++m) score.per_module[m] = Figures(std::move(per[m]));
  return score;
}

}  // namespace

double ShareInsideBox(const std::vector<Eigen::Vector3d>& points_mm, const Eigen::Vector3d& centre_mm,
                      const Eigen::Vector3d& size_mm) {
  if (points_mm.empty()) return 0;
  const Eigen::Vector3d lo = centre_mm - 0.5 * size_mm, hi = centre_mm + 0.5 * size_mm;
  const auto inside = std::count_if(points_mm.begin(), points_mm.end(), [&](const Eigen::Vector3d& p) {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  });
  return double(inside) / double(points_mm.size());
}

}  // namespace stereorig
