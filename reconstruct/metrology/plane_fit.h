// Robust least-squares plane fit: RANSAC on 3-point planes for the inliers,
// then the orthogonal-regression plane (smallest principal axis of the
// inliers' scatter), which minimises the sum of squared orthogonal distances
// exactly. VDI/VDE 2634-2's flatness F is the range of its residuals.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

struct PlaneFitOptions {
  int ransac_iterations = 300;
  double inlier_threshold_mm = 0.5;
  unsigned seed = 1;
  void Check() const;
};

struct PlaneFit {
  bool ok = false;
  std::string message;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double offset_mm = 0;                               // plane: normal . p = offset_mm
  std::vector<int> inliers;
  std::vector<double> residuals_mm;  // signed, parallel to `inliers`
  double rms_mm = 0;
};

PlaneFit FitPlaneRobust(const std::vector<Eigen::Vector3d>& points, const PlaneFitOptions& options);
PlaneFit FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices);

}  // namespace stereorig
