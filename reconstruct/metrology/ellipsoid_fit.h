// Robust least-squares ellipsoid fit, for hole filling with an ellipsoidal
// prior (a tuber): RANSAC on small samples, each fitted with the algebraic
// quadric (the smallest singular vector of the design matrix, on
// normalised coordinates) and kept only if it is an ellipsoid; then
// Levenberg-Marquardt on the Sampson (first-order geometric) distance over
// all inliers, re-segmented once.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

struct EllipsoidFitOptions {
  int ransac_iterations = 300;       // sample hypotheses; default 300
  int sample_size = 12;              // points per hypothesis (>= 9); default 12, steadier than 9 on noisy caps
  double inlier_threshold_mm = 0.5;  // |distance to the surface| for an inlier, mm; default 0.5
  double max_semi_axis_mm = 0;       // > 0: hypotheses with a longer semi-axis are skipped; default 0 (none)
  int max_scoring_points = 2000;     // RANSAC scores hypotheses on at most ~this many points; default 2000
  unsigned seed = 1;                 // RANSAC sampling; fixed => deterministic
  void Check() const;                // throws InputError
};

struct EllipsoidFit {
  bool ok = false;
  std::string message;  // why not ok
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  // Columns: the ellipsoid's axes in the points' frame (a rotation, det +1).
  Eigen::Matrix3d frame_from_ellipsoid = Eigen::Matrix3d::Identity();
  Eigen::Vector3d semi_axes_mm = Eigen::Vector3d::Ones();  // along those columns
  std::vector<int> inliers;                                // indices into the input points
  std::vector<double> residuals_mm;                        // Sampson distance, parallel to `inliers`
  double rms_mm = 0;
  // Signed first-order distance of p to the surface (> 0 outside).
  double Distance(const Eigen::Vector3d& p) const;
  // The surface point at polar angle theta (from the ellipsoid's third
  // axis) and azimuth phi, and its outward unit normal.
  Eigen::Vector3d SurfacePoint(double theta, double phi, Eigen::Vector3d* normal) const;
};

// points: (N), mm. Fewer than 20 points: not ok.
EllipsoidFit FitEllipsoidRobust(const std::vector<Eigen::Vector3d>& points, const EllipsoidFitOptions& options);

}  // namespace stereorig
