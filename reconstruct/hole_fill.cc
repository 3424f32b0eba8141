#include "reconstruct/hole_fill.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <functional>

#include <limits>

#include "reconstruct/metrology/cylinder_fit.h"
#include "reconstruct/metrology/ellipsoid_fit.h"
#include "reconstruct/metrology/sphere_fit.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/proximity_grid.h"
#include "reconstruct/residual_field.h"

namespace stereorig {

namespace {

// The fitted model as a closed lattice of surface samples: rows i in
// [0, rows], columns j in [0, cols) wrapping around, with d/di x d/dj
// pointing out of the surface (so the cells' triangles face outwards).
struct ModelLattice {
  int rows = 0, cols = 0;
  std::function<Eigen::Vector3d(int i, int j, Eigen::Vector3d* normal)> sample;
  // p's signed distance to the model along the model's normal (> 0
  // outside), and *foot, where that normal meets the surface; NaN where p
  // is off the modelled surface (beyond a cylinder's extent).
  std::function<double(const Eigen::Vector3d& p, Eigen::Vector3d* foot)> residual;
  std::string description;  // the fitted model, one line
};

constexpr double kNotOnModel = std::numeric_limits<double>::quiet_NaN();

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
      lattice->residual = [=](const Eigen::Vector3d& p, Eigen::Vector3d* foot) {
        const Eigen::Vector3d v = p - c;
        const double rho = v.norm();
        if (!(rho > 0)) return kNotOnModel;
        *foot = c + r / rho * v;
        return rho - r;
      };
      std::snprintf(
          buf, sizeof buf,
          "sphere centre (%.3f, %.3f, %.3f) mm, radius %.3f mm, fit rms %.3f mm, %zu of %zu fitted points inliers",
          c.x(), c.y(), c.z(), r, fit.rms_mm, fit.inliers.size(), pts.size());
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
      const Eigen::Vector3d axis_point = fit.axis_point_mm;
      lattice->residual = [=](const Eigen::Vector3d& p, Eigen::Vector3d* foot) {
        const Eigen::Vector3d v = p - axis_point;
        const double along = v.dot(d);
        const Eigen::Vector3d radial = v - along * d;
        const double rho = radial.norm();
        if (std::abs(along) > 0.5 * len || !(rho > 0)) return kNotOnModel;  // a cap: not modelled
        *foot = axis_point + along * d + r / rho * radial;
        return rho - r;
      };
      std::snprintf(buf, sizeof buf,
                    "cylinder axis through (%.3f, %.3f, %.3f) mm along (%.4f, %.4f, %.4f), radius %.3f mm, length "
                    "%.1f mm, fit rms %.3f mm, %zu of %zu fitted points inliers",
                    fit.axis_point_mm.x(), fit.axis_point_mm.y(), fit.axis_point_mm.z(), d.x(), d.y(), d.z(), r, len,
                    fit.rms_mm, fit.inliers.size(), pts.size());
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
      // Along the normal of the level set through p (x'A x = const), where
      // it meets the ellipsoid: a quadratic in the step. The line leaves p
      // at an angle of order |distance| x curvature to the surface's normal
      // at the foot, so its length differs from the orthogonal distance by
      // a second-order term (< 0.01 mm for 2 mm on a 17 mm radius of
      // curvature).
      const Eigen::Matrix3d r = fit.frame_from_ellipsoid;
      const Eigen::Vector3d c = fit.center_mm, inv_a2 = a.cwiseProduct(a).cwiseInverse();
      lattice->residual = [=](const Eigen::Vector3d& p, Eigen::Vector3d* foot) {
        const Eigen::Vector3d u = r.transpose() * (p - c);
        const Eigen::Vector3d g = u.cwiseProduct(inv_a2);
        if (!(g.norm() > 0)) return kNotOnModel;
        const Eigen::Vector3d v = g.normalized();  // outward
        const double qa = v.cwiseProduct(v).dot(inv_a2), qb = 2 * v.dot(g), qc = u.dot(g) - 1;
        const double disc = qb * qb - 4 * qa * qc;
        if (disc < 0) return kNotOnModel;
        // The root nearest to p (qb = 2|g| > 0; the other root is across
        // the ellipsoid), in the form without cancellation near the surface.
        const double t = -2 * qc / (qb + std::sqrt(disc));
        *foot = c + r * (u + t * v);
        return -t;
      };
      std::snprintf(buf, sizeof buf,
                    "ellipsoid centre (%.3f, %.3f, %.3f) mm, semi-axes (%.3f, %.3f, %.3f) mm, fit rms %.3f mm, %zu "
                    "of %zu fitted points inliers",
                    fit.center_mm.x(), fit.center_mm.y(), fit.center_mm.z(), a.x(), a.y(), a.z(), fit.rms_mm,
                    fit.inliers.size(), pts.size());
      break;
    }
    case ShapeModel::kNone:
      return *why = "no shape model (shape_model: none)", false;
  }
  lattice->description = buf;
  return true;
}

// The field at every lattice sample, (rows + 1) x cols, row-major. It is
// evaluated on every step-th row and column (wrapping) and interpolated
// bilinearly in between: with step x spacing <= l / 4 the interpolation
// error, ~ (step x spacing)^2 / 8 x |field''| with |field''| ~ signal / l^2,
// stays below 1% of the field's amplitude, and the Gaussian-process sums
// (one per evaluation, over every fitted point) drop ~step^2-fold.
std::vector<double> FieldOnLattice(const ModelLattice& lattice, const ResidualField& field, double spacing_mm,
                                   int threads) {
  const int rows = lattice.rows, cols = lattice.cols;
  std::vector<double> out(size_t(rows + 1) * cols, 0.0);
  if (!field.active()) return out;
  const int step = std::max(1, int(field.length_mm() / (4 * spacing_mm)));
  // Coarse rows 0, step, ..., rows; coarse columns 0, step, ... (then the
  // wrap back to column 0, at index cols).
  std::vector<int> rs, cs;
  for (int i = 0; i < rows; i += step) rs.push_back(i);
  rs.push_back(rows);
  for (int j = 0; j < cols; j += step) cs.push_back(j);
  const int ncs = int(cs.size());
  std::vector<double> coarse(rs.size() * cs.size());
  ParallelForChunks(int(coarse.size()), threads, [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      Eigen::Vector3d n;
      coarse[k] = field.Predict(lattice.sample(rs[k / ncs], cs[k % ncs], &n));
    }
  });
  for (int i = 0; i <= rows; ++i) {
    const int a = std::min(int(rs.size()) - 2, i / step);
    const double ti = double(i - rs[a]) / (rs[a + 1] - rs[a]);
    for (int j = 0; j < cols; ++j) {
      const int b = j / step, b1 = (b + 1) % ncs;
      const int j1 = b + 1 < ncs ? cs[b + 1] : cols;
      const double tj = double(j - cs[b]) / (j1 - cs[b]);
      const double* r0 = &coarse[size_t(a) * ncs];
      const double* r1 = &coarse[size_t(a + 1) * ncs];
      out[size_t(i) * cols + j] = (1 - ti) * ((1 - tj) * r0[b] + tj * r0[b1]) + ti * ((1 - tj) * r1[b] + tj * r1[b1]);
    }
  }
  return out;
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

  // What the model misses, as a smooth field (residual_field.h): the fill
  // follows it (a tuber's bumps) and returns to the model far from data.
  ResidualField field;
  if (options.fill_follow_residuals) {
    std::vector<Eigen::Vector3d> feet;
    std::vector<double> residuals;
    feet.reserve(measured.size());
    residuals.reserve(measured.size());
    for (size_t i = 0; i < measured.size(); ++i) {
      if (measured.module[i] == kFilledModule) continue;
      Eigen::Vector3d foot;
      const double r = lattice.residual(measured.xyz_mm[i].cast<double>(), &foot);
      if (std::isnan(r)) continue;
      feet.push_back(foot);
      residuals.push_back(r);
    }
    ResidualFieldOptions fo;
    fo.length_mm = options.fill_residual_length_mm;
    field = ResidualField::Fit(feet, residuals, fo);
  }

  // Each lattice sample, moved along the model normal by the field; kept
  // where no measured point lies within 2 spacings: what no module saw.
  const int rows = lattice.rows, cols = lattice.cols;
  const size_t samples = size_t(rows + 1) * cols;
  const int threads = options.match.num_threads;
  const std::vector<double> offset = FieldOnLattice(lattice, field, options.fill_spacing_mm, threads);
  std::vector<Eigen::Vector3d> point(samples), normal(samples);
  std::vector<char> keep(samples, 0);
  {
    const ProximityGrid seen(measured.xyz_mm, 2 * options.fill_spacing_mm);
    const double radius = 2 * options.fill_spacing_mm;
    ParallelForChunks(int(samples), threads, [&](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        point[k] = lattice.sample(k / cols, k % cols, &normal[k]) + offset[k] * normal[k];
        keep[k] = !seen.AnyWithin(point[k], radius);
      }
    });
  }
  // The mesh's vertices are the cloud's points: the fill's triangles index
  // the points appended here.
  std::vector<int> vertex(samples, -1);
  const int first_vertex = int(cloud->size());
  int added = 0;
  for (size_t k = 0; k < samples; ++k) {
    if (!keep[k]) continue;
    vertex[k] = first_vertex + added;
    cloud->xyz_mm.push_back(point[k].cast<float>());
    cloud->normal.push_back(normal[k].cast<float>());
    cloud->intensity.push_back(0);
    cloud->module.push_back(kFilledModule);
    cloud->confidence.push_back(0.0f);
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
  result.message =
      lattice.description + "; " +
      (options.fill_follow_residuals ? field.description()
                                     : std::string("residual field not used (fill_follow_residuals: false)"));
  return result;
}

}  // namespace stereorig
