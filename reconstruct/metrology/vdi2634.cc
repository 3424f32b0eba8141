#include "reconstruct/metrology/vdi2634.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "calib/core/input_error.h"
#include "reconstruct/metrology/plane_fit.h"
#include "reconstruct/metrology/sphere_fit.h"

namespace stereorig {

void VerifyOptions::Check() const {
  if (excluded_fraction_max < 0 || excluded_fraction_max > 0.05) {
    throw InputError("verify options", "excluded_fraction_max must be in [0, 0.05]");
  }
  if (min_points < 10) throw InputError("verify options", "min_points must be >= 10");
  if (ballbar_shaft_cone_deg < 0 || ballbar_shaft_cone_deg >= 90) {
    throw InputError("verify options", "ballbar_shaft_cone_deg must be in [0, 90)");
  }
  if (plate_edge_margin_mm < 0) throw InputError("verify options", "plate_edge_margin_mm must not be negative");
}

bool ArtifactEvaluation::pass() const {
  return std::all_of(figures.begin(), figures.end(), [](const Figure& f) { return f.pass; });
}

namespace {

Figure MakeFigure(const std::string& name, double value, double mpe) {
  return {name, value, mpe, std::abs(value) <= mpe};
}

// Drops the largest-|residual| points, at most `fraction` of them, and
// returns the kept indices.
std::vector<int> ExcludeWorst(const std::vector<int>& indices, const std::vector<double>& residuals, double fraction,
                              int* excluded) {
  const int n = static_cast<int>(indices.size());
  *excluded = static_cast<int>(std::floor(fraction * n));
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(residuals[a]) < std::abs(residuals[b]); });
  std::vector<int> kept;
  for (int k = 0; k < n - *excluded; ++k) kept.push_back(indices[order[k]]);
  std::sort(kept.begin(), kept.end());
  return kept;
}

void ResidualStats(const std::vector<double>& r, ArtifactEvaluation* e) {
  double sa = 0, s = 0, ss = 0;
  for (double x : r) {
    sa += std::abs(x);
    s += x;
    ss += x * x;
  }
  const double n = static_cast<double>(r.size());
  e->residual_mean_abs_mm = sa / n;
  e->residual_std_mm = std::sqrt(std::max(0.0, ss / n - (s / n) * (s / n)));
}

double Range(const std::vector<double>& r) {
  const auto [lo, hi] = std::minmax_element(r.begin(), r.end());
  return *hi - *lo;
}

// Segmentation rounds: a point set and its fit are iterated until the set
// no longer changes (2-4 rounds in practice).
constexpr int kMaxSegmentationRounds = 20;

// One sphere of known nominal radius: segment, fit, exclude, refit.
SphereFit FitArtifactSphere(const std::vector<Eigen::Vector3d>& pts, double nominal_radius, double band,
                            const VerifyOptions& o, int* excluded) {
  SphereFitOptions so;
  so.inlier_threshold_mm = band;
  so.expected_radius_mm = nominal_radius;
  so.radius_tolerance_mm = std::max(band, 0.1 * nominal_radius);
  so.ransac_iterations = 1000;
  so.seed = o.seed;
  SphereFit fit = FitSphereRobust(pts, so);
  if (!fit.ok) return fit;
  // The artifact's points are those within the band of the fitted sphere:
  // iterate to that fixed point, so the set does not depend on RANSAC's path.
  for (int it = 0; it < kMaxSegmentationRounds; ++it) {
    std::vector<int> in;
    for (int i = 0; i < static_cast<int>(pts.size()); ++i)
      if (std::abs((pts[i] - fit.center_mm).norm() - fit.radius_mm) < band) in.push_back(i);
    if (in == fit.inliers) break;
    fit = RefineSphere(pts, in, fit.center_mm, fit.radius_mm, 50);
    if (!fit.ok) return fit;
  }
  const std::vector<int> kept = ExcludeWorst(fit.inliers, fit.residuals_mm, o.excluded_fraction_max, excluded);
  return RefineSphere(pts, kept, fit.center_mm, fit.radius_mm, 50);
}

}  // namespace

ArtifactEvaluation EvaluateArtifact(const Artifact& a, const std::vector<Eigen::Vector3d>& pts, const VerifyOptions& o,
                                    const std::string& where) {
  o.Check();
  ArtifactEvaluation e;
  e.type = a.type;
  e.points_total = static_cast<int>(pts.size());
  if (e.points_total < o.min_points) {
    throw InputError(where, "only " + std::to_string(e.points_total) + " points; at least " +
                                std::to_string(o.min_points) + " are needed on the artifact");
  }
  auto require_points = [&](int n, const char* what) {
    if (n < o.min_points) {
      throw InputError(where, std::string("only ") + std::to_string(n) + " points lie on the " + what + "; at least " +
                                  std::to_string(o.min_points) + " are needed");
    }
  };
  switch (a.type) {
    case ArtifactType::kSphere: {
      const double band = o.segmentation_band_mm > 0 ? o.segmentation_band_mm : a.mpe.probing_form_mm;
      int excluded = 0;
      const SphereFit fit = FitArtifactSphere(pts, 0.5 * a.sphere_diameter_mm, band, o, &excluded);
      if (!fit.ok) throw InputError(where, "no sphere of the certified size found in the cloud: " + fit.message);
      require_points(static_cast<int>(fit.inliers.size()) + excluded, "sphere");
      e.points_on_artifact = static_cast<int>(fit.inliers.size()) + excluded;
      e.points_excluded = excluded;
      e.sphere_centers_mm = {fit.center_mm};
      e.sphere_diameters_mm = {2 * fit.radius_mm};
      e.figures = {MakeFigure("P_F", Range(fit.residuals_mm), a.mpe.probing_form_mm),
                   MakeFigure("P_S", 2 * fit.radius_mm - a.sphere_diameter_mm, a.mpe.probing_size_mm)};
      ResidualStats(fit.residuals_mm, &e);
      break;
    }
    case ArtifactType::kBallBar: {
      const double band = o.segmentation_band_mm > 0 ? o.segmentation_band_mm : a.mpe.sphere_spacing_mm;
      const double r = 0.5 * a.sphere_diameter_mm;
      std::vector<double> all_residuals;
      std::vector<Eigen::Vector3d> remaining = pts;
      int excluded_total = 0, on_artifact = 0;
      for (int ball = 0; ball < 2; ++ball) {
        int excluded = 0;
        const SphereFit fit = FitArtifactSphere(remaining, r, band, o, &excluded);
        if (!fit.ok) {
          throw InputError(where, "ball " + std::to_string(ball + 1) + " of the ball bar not found: " + fit.message);
        }
        require_points(static_cast<int>(fit.inliers.size()) + excluded, "ball bar's spheres");
        excluded_total += excluded;
        on_artifact += static_cast<int>(fit.inliers.size()) + excluded;
        e.sphere_centers_mm.push_back(fit.center_mm);
        e.sphere_diameters_mm.push_back(2 * fit.radius_mm);
        all_residuals.insert(all_residuals.end(), fit.residuals_mm.begin(), fit.residuals_mm.end());
        // Remove everything near this ball before looking for the other one.
        std::vector<Eigen::Vector3d> rest;
        for (const auto& p : remaining)
          if ((p - fit.center_mm).norm() > fit.radius_mm + band) rest.push_back(p);
        remaining.swap(rest);
      }
      // Second pass: with both centres known, each ball's points are those
      // within the band of its sphere and outside the shaft's cone about the
      // bar axis; the sets and fits are iterated to their fixed point, then
      // the worst points are excluded and each ball is refitted.
      {
        const double cos_cone = std::cos(o.ballbar_shaft_cone_deg * M_PI / 180.0);
        std::vector<Eigen::Vector3d> centers = e.sphere_centers_mm;
        std::vector<double> radii = {0.5 * e.sphere_diameters_mm[0], 0.5 * e.sphere_diameters_mm[1]};
        std::vector<int> idx[2];
        for (int round = 0; round < kMaxSegmentationRounds; ++round) {
          bool changed = false;
          std::vector<int> next[2];
          for (int ball = 0; ball < 2; ++ball) {
            const Eigen::Vector3d axis = (centers[1 - ball] - centers[ball]).normalized();
            for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
              const Eigen::Vector3d d = pts[i] - centers[ball];
              if (std::abs(d.norm() - radii[ball]) >= band || d.norm() < 1e-9 || d.normalized().dot(axis) > cos_cone)
                continue;
              next[ball].push_back(i);
            }
            require_points(static_cast<int>(next[ball].size()), "ball bar's spheres (outside the shaft cone)");
            changed = changed || next[ball] != idx[ball];
          }
          if (!changed) break;
          for (int ball = 0; ball < 2; ++ball) {
            idx[ball].swap(next[ball]);
            const SphereFit fit = RefineSphere(pts, idx[ball], centers[ball], radii[ball], 50);
            if (!fit.ok) throw InputError(where, "ball " + std::to_string(ball + 1) + " refit failed: " + fit.message);
            centers[ball] = fit.center_mm;
            radii[ball] = fit.radius_mm;
          }
        }
        all_residuals.clear();
        excluded_total = 0;
        on_artifact = 0;
        for (int ball = 0; ball < 2; ++ball) {
          std::vector<double> res;
          for (int i : idx[ball]) res.push_back((pts[i] - centers[ball]).norm() - radii[ball]);
          int excluded = 0;
          const std::vector<int> kept = ExcludeWorst(idx[ball], res, o.excluded_fraction_max, &excluded);
          const SphereFit fit = RefineSphere(pts, kept, centers[ball], radii[ball], 50);
          if (!fit.ok) throw InputError(where, "ball " + std::to_string(ball + 1) + " refit failed: " + fit.message);
          e.sphere_centers_mm[ball] = fit.center_mm;
          e.sphere_diameters_mm[ball] = 2 * fit.radius_mm;
          all_residuals.insert(all_residuals.end(), fit.residuals_mm.begin(), fit.residuals_mm.end());
          excluded_total += excluded;
          on_artifact += static_cast<int>(idx[ball].size());
        }
      }
      e.points_on_artifact = on_artifact;
      e.points_excluded = excluded_total;
      const double distance = (e.sphere_centers_mm[0] - e.sphere_centers_mm[1]).norm();
      e.figures = {MakeFigure("SD", distance - a.center_distance_mm, a.mpe.sphere_spacing_mm)};
      ResidualStats(all_residuals, &e);
      break;
    }
    case ArtifactType::kPlate: {
      const double band = o.segmentation_band_mm > 0 ? o.segmentation_band_mm : a.mpe.flatness_mm;
      PlaneFitOptions po;
      po.inlier_threshold_mm = band;
      po.seed = o.seed;
      PlaneFit fit = FitPlaneRobust(pts, po);
      if (!fit.ok) throw InputError(where, "no plane found in the cloud: " + fit.message);
      // The face only: erode the segmented points' in-plane extent (along
      // their principal axes) by the edge margin.
      {
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (int i : fit.inliers) mean += pts[i];
        mean /= static_cast<double>(fit.inliers.size());
        Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
        for (int i : fit.inliers) scatter += (pts[i] - mean) * (pts[i] - mean).transpose();
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(scatter);
        const Eigen::Vector3d u = es.eigenvectors().col(2), v = es.eigenvectors().col(1);
        double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
        for (int i : fit.inliers) {
          const Eigen::Vector3d d = pts[i] - mean;
          u0 = std::min(u0, d.dot(u));
          u1 = std::max(u1, d.dot(u));
          v0 = std::min(v0, d.dot(v));
          v1 = std::max(v1, d.dot(v));
        }
        const double m = o.plate_edge_margin_mm;
        std::vector<int> face;
        for (int i : fit.inliers) {
          const Eigen::Vector3d d = pts[i] - mean;
          if (d.dot(u) > u0 + m && d.dot(u) < u1 - m && d.dot(v) > v0 + m && d.dot(v) < v1 - m) face.push_back(i);
        }
        fit = FitPlaneLeastSquares(pts, face);
        if (!fit.ok) throw InputError(where, "the plate's face is too small after the edge margin: " + fit.message);
      }
      require_points(static_cast<int>(fit.inliers.size()), "plate");
      int excluded = 0;
      const std::vector<int> kept = ExcludeWorst(fit.inliers, fit.residuals_mm, o.excluded_fraction_max, &excluded);
      fit = FitPlaneLeastSquares(pts, kept);
      e.points_on_artifact = static_cast<int>(kept.size()) + excluded;
      e.points_excluded = excluded;
      e.plane_normal = fit.normal;
      e.plane_offset_mm = fit.offset_mm;
      e.figures = {MakeFigure("F", Range(fit.residuals_mm), a.mpe.flatness_mm)};
      ResidualStats(fit.residuals_mm, &e);
      break;
    }
  }
  return e;
}

VerifySummary Summarise(const std::vector<ArtifactEvaluation>& positions) {
  VerifySummary s;
  std::map<std::string, Figure> worst;
  for (const auto& p : positions) {
    for (const Figure& f : p.figures) {
      auto it = worst.find(f.name);
      if (it == worst.end() || std::abs(f.value_mm) > std::abs(it->second.value_mm)) worst[f.name] = f;
    }
  }
  s.pass = !positions.empty();
  for (const auto& [name, f] : worst) {
    s.worst.push_back(f);
    s.pass = s.pass && f.pass;
  }
  return s;
}

}  // namespace stereorig
