// Test support: noisy partial clouds of known shapes, as two facing
// modules see them (cameras at the origin looking along +z, and at
// z = 2 * centre.z looking along -z). A surface sample is kept if either
// camera sees its front within 70 degrees of grazing; convex shapes hide
// nothing else. Noise: Gaussian along the normal; normals tilted by a
// Gaussian angle; plus uniform outliers in the shape's bounding box.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <tuple>
#include <vector>

namespace stereorig::testing {

struct NoisyCloud {
  std::vector<Eigen::Vector3d> points, normals;  // (N) each
  int outliers = 0;                              // the last `outliers` entries
};

struct NoiseSpec {
  int points = 20000;
  double noise_mm = 0.05;          // along the normal, 1 sigma
  double normal_noise_deg = 3.0;   // 1 sigma per axis
  double outlier_fraction = 0.05;  // of `points`, uniform in the box
  double box_half_size_mm = 50;    // about the shape's centre
  double max_view_angle_deg = 70;  // from the camera's line of sight to the normal
  unsigned seed = 1;
};

// surface(u, v, &normal) -> point, for u, v uniform in [0, 1).
inline NoisyCloud SeenByTwoFacingCameras(
    const std::function<Eigen::Vector3d(double, double, Eigen::Vector3d*)>& surface, const Eigen::Vector3d& centre,
    const NoiseSpec& spec) {
  NoisyCloud cloud;
  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<double> u(0, 1), box(-spec.box_half_size_mm, spec.box_half_size_mm);
  std::normal_distribution<double> noise(0, spec.noise_mm), tilt(0, spec.normal_noise_deg * M_PI / 180);
  const Eigen::Vector3d cameras[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 2 * centre.z())};
  const double cos_max = std::cos(spec.max_view_angle_deg * M_PI / 180);
  const int inliers = static_cast<int>(std::lround(spec.points * (1 - spec.outlier_fraction)));
  while (static_cast<int>(cloud.points.size()) < inliers) {
    Eigen::Vector3d n;
    const Eigen::Vector3d p = surface(u(rng), u(rng), &n);
    bool seen = false;
    for (const auto& c : cameras) seen = seen || n.dot((c - p).normalized()) > cos_max;
    if (!seen) continue;
    cloud.points.push_back(p + noise(rng) * n);
    cloud.normals.push_back((Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitY()) * n)
                                .normalized());
  }
  while (static_cast<int>(cloud.points.size()) < spec.points) {
    cloud.points.push_back(centre + Eigen::Vector3d(box(rng), box(rng), box(rng)));
    cloud.normals.push_back(Eigen::Vector3d(box(rng), box(rng), box(rng)).normalized());
    ++cloud.outliers;
  }
  return cloud;
}

// A cylinder's lateral surface: axis through `centre` along `axis`, radius
// r, length len (centred).
inline std::function<Eigen::Vector3d(double, double, Eigen::Vector3d*)> CylinderSurface(const Eigen::Vector3d& centre,
                                                                                        const Eigen::Vector3d& axis,
                                                                                        double r, double len) {
  const Eigen::Vector3d d = axis.normalized(), e1 = d.unitOrthogonal(), e2 = d.cross(e1);
  return [=](double a, double b, Eigen::Vector3d* n) {
    const double phi = 2 * M_PI * a;
    *n = std::cos(phi) * e1 + std::sin(phi) * e2;
    return Eigen::Vector3d(centre + (b - 0.5) * len * d + r * *n);
  };
}

// A sphere's cap: the points within `half_angle_deg` of `axis` seen from
// `centre`, uniform in area (cos of the polar angle uniform).
inline std::function<Eigen::Vector3d(double, double, Eigen::Vector3d*)> SphereCapSurface(const Eigen::Vector3d& centre,
                                                                                         const Eigen::Vector3d& axis,
                                                                                         double r,
                                                                                         double half_angle_deg) {
  const Eigen::Vector3d z = axis.normalized(), x = z.unitOrthogonal(), y = z.cross(x);
  const double cos_max = std::cos(half_angle_deg * M_PI / 180);
  return [=](double a, double b, Eigen::Vector3d* n) {
    const double c = 1 - a * (1 - cos_max), s = std::sqrt(std::max(0.0, 1 - c * c)), phi = 2 * M_PI * b;
    *n = c * z + s * (std::cos(phi) * x + std::sin(phi) * y);
    return Eigen::Vector3d(centre + r * *n);
  };
}

// `count` samples of a surface, each moved along its normal by Gaussian noise
// of `noise_mm` (1 sigma): every point seen, no outliers.
inline std::vector<Eigen::Vector3d> NoisySurfaceSamples(
    const std::function<Eigen::Vector3d(double, double, Eigen::Vector3d*)>& surface, int count, double noise_mm,
    std::mt19937* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> noise(0, noise_mm);
  std::vector<Eigen::Vector3d> points;
  points.reserve(count);
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d n;
    const Eigen::Vector3d p = surface(u(*rng), u(*rng), &n);
    points.push_back(p + noise(*rng) * n);
  }
  return points;
}

// Noise shared by neighbouring points, as a reconstruction's is (a matching
// window's footprint: the demo's residuals correlate 0.87 at 0.2-0.5 mm and
// 0.26 at 1-2 mm, none beyond 2 mm): a random field, independent N(0,
// sigma) values on a lattice of `cell_mm` trilinearly interpolated (it
// correlates over up to 2 cells), along each point's normal, plus
// independent noise.
inline std::vector<Eigen::Vector3d> CorrelatedNoiseSamples(
    const std::function<Eigen::Vector3d(double, double, Eigen::Vector3d*)>& surface, int count, double field_mm,
    double cell_mm, double white_mm, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> field(0, field_mm), white(0, white_mm);
  std::map<std::tuple<long, long, long>, double> lattice;  // drawn as the points reach it
  const Eigen::Vector3d offset_mm(u(*rng) * cell_mm, u(*rng) * cell_mm, u(*rng) * cell_mm);
  auto at = [&](long i, long j, long k) {
    const auto [it, fresh] = lattice.try_emplace({i, j, k}, 0.0);
    if (fresh) it->second = field(*rng);
    return it->second;
  };
  std::vector<Eigen::Vector3d> points;
  for (int n = 0; n < count; ++n) {
    Eigen::Vector3d normal;
    const Eigen::Vector3d p = surface(u(*rng), u(*rng), &normal);
    const Eigen::Vector3d q = (p + offset_mm) / cell_mm;
    const long i = static_cast<long>(std::floor(q.x())), j = static_cast<long>(std::floor(q.y())),
               k = static_cast<long>(std::floor(q.z()));
    const Eigen::Vector3d f = q - Eigen::Vector3d(i, j, k);
    double e = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (int c = 0; c < 2; ++c)
          e += (a ? f.x() : 1 - f.x()) * (b ? f.y() : 1 - f.y()) * (c ? f.z() : 1 - f.z()) * at(i + a, j + b, k + c);
    points.push_back(p + (e + white(*rng)) * normal);
  }
  return points;
}

// An ellipsoid: centre, frame_from_ellipsoid rotation, semi-axes.
inline std::function<Eigen::Vector3d(double, double, Eigen::Vector3d*)> EllipsoidSurface(
    const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& axes) {
  return [=](double a, double b, Eigen::Vector3d* n) {
    const double z = 2 * a - 1, phi = 2 * M_PI * b, s = std::sqrt(1 - z * z);
    const Eigen::Vector3d w(s * std::cos(phi), s * std::sin(phi), z);
    *n = (rotation * w.cwiseQuotient(axes)).normalized();
    return Eigen::Vector3d(centre + rotation * axes.cwiseProduct(w));
  };
}

// Upper bound on the distance from p to the ellipsoid: the distance to the
// surface point on the ray from the centre through p (the true, orthogonal
// distance is never larger).
inline double EllipsoidDistanceBound(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                                     const Eigen::Vector3d& axes, const Eigen::Vector3d& p) {
  const Eigen::Vector3d u = rotation.transpose() * (p - centre);
  const double s = u.cwiseQuotient(axes).norm();  // 1 on the surface
  return u.norm() * std::abs(1 - 1 / s);
}

}  // namespace stereorig::testing
