// Robust least-squares cylinder fit, for hole filling with a cylindrical
// prior (a cup): RANSAC on pairs of oriented points (two surface normals fix
// the axis direction, n1 x n2, and their lines meet on the axis), then
// Levenberg-Marquardt on the geometric distance | |(p - a) x d| - r | over
// all inliers, re-segmented once. The finite extent along the axis is the
// inliers' (robust) range.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

struct CylinderFitOptions {
  int ransac_iterations = 500;       // 2-point hypotheses; default 500
  double inlier_threshold_mm = 0.5;  // |distance to the surface| for an inlier, mm; default 0.5
  double max_normal_angle_deg = 30;  // RANSAC: a point's normal within this of the radial direction; default 30
  double max_radius_mm = 0;          // > 0: hypotheses with a larger radius are skipped; default 0 (none)
  double extent_quantile = 0.002;    // the axial extent runs between these quantiles of the inliers; default 0.2%
  int max_scoring_points = 2000;     // RANSAC scores hypotheses on at most ~this many points; default 2000
  unsigned seed = 1;                 // RANSAC sampling; fixed => deterministic
  void Check() const;                // throws InputError
};

struct CylinderFit {
  bool ok = false;
  std::string message;                                        // why not ok
  Eigen::Vector3d axis_point_mm = Eigen::Vector3d::Zero();    // on the axis, at the middle of the extent
  Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitZ();  // unit
  double radius_mm = 0;
  double length_mm = 0;              // extent along the axis, centred on axis_point_mm
  std::vector<int> inliers;          // indices into the input points
  std::vector<double> residuals_mm;  // signed distance to the surface, parallel to `inliers`
  double rms_mm = 0;
  // Signed distance of p to the infinite cylinder surface (> 0 outside).
  double Distance(const Eigen::Vector3d& p) const;
};

// points, normals: (N) each, mm and unit vectors (normals: the measured
// surface's, either sign). Fewer than 10 points or no normals: not ok.
CylinderFit FitCylinderRobust(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                              const CylinderFitOptions& options);

}  // namespace stereorig
