#include "reconstruct/hole_fill.h"

#include <cmath>
#include <cstdio>

#include "reconstruct/kd_tree.h"
#include "reconstruct/metrology/sphere_fit.h"

namespace stereorig {

HoleFillResult FillHolesFromModel(const PointCloud& measured, const RuntimeOptions& options, PointCloud* cloud,
                                  Mesh* mesh) {
  HoleFillResult result;
  if (options.shape_model != ShapeModel::kSphere) {
    result.message = std::string("shape model ") + ShapeModelName(options.shape_model) + " is not built yet";
    return result;
  }
  if (measured.size() < 100) {
    result.message = "too few points to fit a sphere";
    return result;
  }
  // Fit on a subsample (every k-th point): the fit's precision is far below
  // the fill's tolerance well before 20k points.
  std::vector<Eigen::Vector3d> pts;
  const size_t step = std::max<size_t>(1, measured.size() / 20000);
  for (size_t i = 0; i < measured.size(); i += step) pts.push_back(measured.xyz_mm[i].cast<double>());
  SphereFitOptions so;
  so.inlier_threshold_mm = 0.3;
  const SphereFit fit = FitSphereRobust(pts, so);
  if (!fit.ok) {
    result.message = "sphere fit failed: " + fit.message;
    return result;
  }
  if (fit.radius_mm > options.object_size_mm) {
    result.message = "fitted sphere (r = " + std::to_string(fit.radius_mm) + " mm) is larger than object_size_mm";
    return result;
  }
  std::vector<Eigen::Vector3d> all;
  all.reserve(measured.size());
  for (const auto& p : measured.xyz_mm) all.push_back(p.cast<double>());
  const KdTree3 tree(std::move(all));

  const double r = fit.radius_mm, s = options.fill_spacing_mm;
  const int n_polar = std::max(4, int(std::ceil(M_PI * r / s)));
  const int n_azimuth = std::max(8, int(std::ceil(2 * M_PI * r / s)));
  std::vector<int> lattice(size_t(n_polar + 1) * n_azimuth, -1);
  const int first_vertex = int(mesh->vertices_mm.size());
  int added = 0;
  for (int i = 0; i <= n_polar; ++i) {
    const double theta = M_PI * i / n_polar;
    for (int j = 0; j < n_azimuth; ++j) {
      const double phi = 2 * M_PI * j / n_azimuth;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      const Eigen::Vector3d p = fit.center_mm + r * n;
      if (tree.NearestDistance(p) < 2 * s) continue;
      lattice[size_t(i) * n_azimuth + j] = first_vertex + added;
      cloud->xyz_mm.push_back(p.cast<float>());
      cloud->normal.push_back(n.cast<float>());
      cloud->intensity.push_back(0);
      cloud->module.push_back(kFilledModule);
      cloud->confidence.push_back(0.0f);
      mesh->vertices_mm.push_back(p.cast<float>());
      ++added;
    }
  }
  for (int i = 0; i < n_polar; ++i)
    for (int j = 0; j < n_azimuth; ++j) {
      const int jn = (j + 1) % n_azimuth;
      const int a = lattice[size_t(i) * n_azimuth + j], b = lattice[size_t(i) * n_azimuth + jn];
      const int c = lattice[size_t(i + 1) * n_azimuth + j], d = lattice[size_t(i + 1) * n_azimuth + jn];
      // Outward normals: theta grows towards -z, phi counter-clockwise about z.
      if (a >= 0 && b >= 0 && c >= 0) mesh->triangles.emplace_back(a, c, b);
      if (b >= 0 && c >= 0 && d >= 0) mesh->triangles.emplace_back(b, c, d);
    }
  char buf[200];
  std::snprintf(buf, sizeof buf, "sphere centre (%.3f, %.3f, %.3f) mm, radius %.3f mm, fit rms %.3f mm, %zu inliers",
                fit.center_mm.x(), fit.center_mm.y(), fit.center_mm.z(), fit.radius_mm, fit.rms_mm, fit.inliers.size());
  result.ok = true;
  result.added_points = added;
  result.message = buf;
  return result;
}

}  // namespace stereorig
