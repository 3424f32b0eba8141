#include "reconstruct/hole_fill.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <functional>

#include "reconstruct/kd_tree.h"
#include "reconstruct/metrology/cylinder_fit.h"
#include "reconstruct/metrology/ellipsoid_fit.h"
#include "reconstruct/metrology/sphere_fit.h"

namespace stereorig {

namespace {

// The fitted model as a closed lattice of surface samples: rows i in
// [0, rows], columns j in [0, cols) wrapping around, with d/di x d/dj
// pointing out of the surface (so the cells' triangles face outwards).
struct ModelLattice {
  int rows = 0, cols = 0;
  std::function<Eigen::Vector3d(int i, int j, Eigen::Vector3d* normal)> sample;
  std::string description;  // the fitted model, one line
};

// A fit is used only if the model explains at least this fraction of the
// measured points: a model of the wrong kind or size can still gather a
// small consensus (a strip of the surface), and must not close holes.
constexpr double kMinInlierFraction = 0.5;

bool ExplainsEnough(const char* model, size_t inliers, size_t points, std::string* why) {
  if (inliers >= kMinInlierFraction * points) return true;
  char buf[200];
  std::snprintf(buf, sizeof buf, "the fitted %s explains only %.0f%% of the points (at least %.0f%% needed)", model,
                100.0 * inliers / points, 100 * kMinInlierFraction);
  *why = buf;
  return false;
}

bool TooLarge(const char* model, const char* what, double size_mm, double object_size_mm, std::string* why) {
  if (size_mm <= object_size_mm) return false;
  char buf[200];
  std::snprintf(buf, sizeof buf, "the fitted %s's %s (%.1f mm) exceeds object_size_mm (%.1f mm)", model, what, size_mm,
                object_size_mm);
  *why = buf;
  return true;
}

// The model's fit to `pts` (normals: parallel to pts), or why there is none.
bool FitModel(const std::vector<Eigen::Vector3d>& pts, const std::vector<Eigen::Vector3d>& normals,
              const RuntimeOptions& o, ModelLattice* lattice, std::string* why) {
  const double s = o.fill_spacing_mm;
  char buf[300];
  switch (o.shape_model) {
    case ShapeModel::kSphere: {
      SphereFitOptions so;
      so.inlier_threshold_mm = 0.3;
      const SphereFit fit = FitSphereRobust(pts, so);
      if (!fit.ok) return *why = "sphere fit failed: " + fit.message, false;
      if (TooLarge("sphere", "diameter", 2 * fit.radius_mm, o.object_size_mm, why) ||
          !ExplainsEnough("sphere", fit.inliers.size(), pts.size(), why))
        return false;
      const double r = fit.radius_mm;
      lattice->rows = std::max(4, int(std::ceil(M_PI * r / s)));
      lattice->cols = std::max(8, int(std::ceil(2 * M_PI * r / s)));
      const int rows = lattice->rows, cols = lattice->cols;
      const Eigen::Vector3d c = fit.center_mm;
      // Rows: polar angle from +z; columns: azimuth.
      lattice->sample = [=](int i, int j, Eigen::Vector3d* n) {
        const double theta = M_PI * i / rows, phi = 2 * M_PI * j / cols;
        *n = Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        return Eigen::Vector3d(c + r * *n);
      };
      std::snprintf(buf, sizeof buf,
                    "sphere centre (%.3f, %.3f, %.3f) mm, radius %.3f mm, fit rms %.3f mm, %zu inliers", c.x(), c.y(),
                    c.z(), r, fit.rms_mm, fit.inliers.size());
      break;
    }
    case ShapeModel::kCylinder: {
      CylinderFitOptions co;
      co.inlier_threshold_mm = 0.5;
      co.max_radius_mm = o.object_size_mm;  // loose: a clear message below beats a silent RANSAC miss
      const CylinderFit fit = FitCylinderRobust(pts, normals, co);
      if (!fit.ok) return *why = "cylinder fit failed: " + fit.message, false;
      if (TooLarge("cylinder", "diameter", 2 * fit.radius_mm, o.object_size_mm, why) ||
          TooLarge("cylinder", "length", fit.length_mm, o.object_size_mm, why) ||
          !ExplainsEnough("cylinder", fit.inliers.size(), pts.size(), why))
        return false;
      const double r = fit.radius_mm, len = fit.length_mm;
      const Eigen::Vector3d d = fit.axis_direction, e1 = d.unitOrthogonal(), e2 = d.cross(e1);
      const Eigen::Vector3d bottom = fit.axis_point_mm - 0.5 * len * d;
      // The lateral surface only, over the measured extent (the caps of a
      // cup are its open top and the floor it stands on). Rows: along the
      // axis; columns: clockwise about it, so d/di x d/dj is outward.
      lattice->rows = std::max(1, int(std::ceil(len / s)));
      lattice->cols = std::max(8, int(std::ceil(2 * M_PI * r / s)));
      const int rows = lattice->rows, cols = lattice->cols;
      lattice->sample = [=](int i, int j, Eigen::Vector3d* n) {
        const double phi = -2 * M_PI * j / cols;
        *n = std::cos(phi) * e1 + std::sin(phi) * e2;
        return Eigen::Vector3d(bottom + len * i / rows * d + r * *n);
      };
      std::snprintf(buf, sizeof buf,
                    "cylinder axis through (%.3f, %.3f, %.3f) mm along (%.4f, %.4f, %.4f), radius %.3f mm, length "
                    "%.1f mm, fit rms %.3f mm, %zu inliers",
                    fit.axis_point_mm.x(), fit.axis_point_mm.y(), fit.axis_point_mm.z(), d.x(), d.y(), d.z(), r, len,
                    fit.rms_mm, fit.inliers.size());
      break;
    }
    case ShapeModel::kEllipsoid: {
      EllipsoidFitOptions eo;
      eo.inlier_threshold_mm = 0.5;
      eo.max_semi_axis_mm = o.object_size_mm;  // loose: a clear message below beats a silent RANSAC miss
      const EllipsoidFit fit = FitEllipsoidRobust(pts, eo);
      if (!fit.ok) return *why = "ellipsoid fit failed: " + fit.message, false;
      if (TooLarge("ellipsoid", "longest axis", 2 * fit.semi_axes_mm.maxCoeff(), o.object_size_mm, why) ||
          !ExplainsEnough("ellipsoid", fit.inliers.size(), pts.size(), why))
        return false;
      const Eigen::Vector3d a = fit.semi_axes_mm;
      lattice->rows = std::max(4, int(std::ceil(M_PI * a.maxCoeff() / s)));
      lattice->cols = std::max(8, int(std::ceil(2 * M_PI * a.maxCoeff() / s)));
      const int rows = lattice->rows, cols = lattice->cols;
      lattice->sample = [=](int i, int j, Eigen::Vector3d* n) {
        return fit.SurfacePoint(M_PI * i / rows, 2 * M_PI * j / cols, n);
      };
      std::snprintf(buf, sizeof buf,
                    "ellipsoid centre (%.3f, %.3f, %.3f) mm, semi-axes (%.3f, %.3f, %.3f) mm, fit rms %.3f mm, %zu "
                    "inliers",
                    fit.center_mm.x(), fit.center_mm.y(), fit.center_mm.z(), a.x(), a.y(), a.z(), fit.rms_mm,
                    fit.inliers.size());
      break;
    }
    case ShapeModel::kNone:
      return *why = "no shape model (shape_model: none)", false;
  }
  lattice->description = buf;
  return true;
}

}  // namespace

HoleFillResult FillHolesFromModel(const PointCloud& measured, const RuntimeOptions& options, PointCloud* cloud,
                                  Mesh* mesh) {
  HoleFillResult result;
  if (measured.size() < 100) {
    result.message =
        "too few points (" + std::to_string(measured.size()) + ") to fit a " + ShapeModelName(options.shape_model);
    return result;
  }
  // Fit on a subsample (every k-th point): the fit's precision is far below
  // the fill's tolerance well before 20k points.
  std::vector<Eigen::Vector3d> pts, normals;
  const size_t step = std::max<size_t>(1, measured.size() / 20000);
  for (size_t i = 0; i < measured.size(); i += step) {
    pts.push_back(measured.xyz_mm[i].cast<double>());
    if (measured.normal.size() == measured.size()) normals.push_back(measured.normal[i].cast<double>());
  }
  ModelLattice lattice;
  if (!FitModel(pts, normals, options, &lattice, &result.message)) return result;

  std::vector<Eigen::Vector3d> all;
  all.reserve(measured.size());
  for (const auto& p : measured.xyz_mm) all.push_back(p.cast<double>());
  const KdTree3 tree(std::move(all));

  // Keep the samples with no measured point within 2 spacings: what no
  // module saw.
  const int rows = lattice.rows, cols = lattice.cols;
  std::vector<int> vertex(size_t(rows + 1) * cols, -1);
  const int first_vertex = int(mesh->vertices_mm.size());
  int added = 0;
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j < cols; ++j) {
      Eigen::Vector3d n;
      const Eigen::Vector3d p = lattice.sample(i, j, &n);
      if (tree.NearestDistance(p) < 2 * options.fill_spacing_mm) continue;
      vertex[size_t(i) * cols + j] = first_vertex + added;
      cloud->xyz_mm.push_back(p.cast<float>());
      cloud->normal.push_back(n.cast<float>());
      cloud->intensity.push_back(0);
      cloud->module.push_back(kFilledModule);
      cloud->confidence.push_back(0.0f);
      mesh->vertices_mm.push_back(p.cast<float>());
      ++added;
    }
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      const int jn = (j + 1) % cols;
      const int a = vertex[size_t(i) * cols + j], b = vertex[size_t(i) * cols + jn];
      const int c = vertex[size_t(i + 1) * cols + j], d = vertex[size_t(i + 1) * cols + jn];
      // Outward: (c - a) x (b - a) = d/di x d/dj.
      if (a >= 0 && b >= 0 && c >= 0) mesh->triangles.emplace_back(a, c, b);
      if (b >= 0 && c >= 0 && d >= 0) mesh->triangles.emplace_back(b, c, d);
    }
  result.ok = true;
  result.added_points = added;
  result.message = lattice.description;
  return result;
}

}  // namespace stereorig
