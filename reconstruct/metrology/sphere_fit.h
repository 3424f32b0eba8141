// Robust least-squares sphere fit: RANSAC on 4-point spheres to find the
// inliers, then Gauss-Newton on the geometric (orthogonal) distance over all
// inliers, radius free. This is the fit VDI/VDE 2634-2 asks for (probing
// error P_F, P_S) and the one hole filling uses for a spherical prior.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

struct SphereFitOptions {
  int ransac_iterations = 500;       // 4-point hypotheses
  double inlier_threshold_mm = 0.5;  // |distance to sphere| for a RANSAC inlier
  // If > 0, RANSAC hypotheses whose radius differs from this by more than
  // radius_tolerance_mm are skipped (a known artifact size narrows the search).
  double expected_radius_mm = 0;
  double radius_tolerance_mm = 0;
  int max_iterations = 50;  // Gauss-Newton
  unsigned seed = 1;        // RANSAC sampling; fixed => deterministic
  // false: the consensus is refined with the radius held at
  // expected_radius_mm (centre only), to *locate* a sphere of known size. A
  // cap whose sagitta lies within inlier_threshold_mm holds a sphere of that
  // size either side of it (seen from outside and from inside), and the
  // 4-point hypothesis may be either: both are refined, the better-fitting
  // kept. (A free radius refined from the wrong side must pass through a
  // plane to reach the right one: on small caps it ran away to spheres
  // kilometres wide.)
  bool refine_radius = true;
  void Check() const;  // throws InputError
};

struct SphereFit {
  bool ok = false;
  std::string message;  // why not ok
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  double radius_mm = 0;
  std::vector<int> inliers;          // indices into the input points
  std::vector<double> residuals_mm;  // signed |p - c| - r, parallel to `inliers`
  double rms_mm = 0;
  // Gauss-Newton's last step was under 1e-6 mm: a fixed point, not a fit
  // stopped at max_iterations while still moving.
  bool converged = false;
};

// points: (N) in mm.
SphereFit FitSphereRobust(const std::vector<Eigen::Vector3d>& points, const SphereFitOptions& options);
// Gauss-Newton only, from `initial`, on exactly these points (no rejection).
SphereFit RefineSphere(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                       const Eigen::Vector3d& initial_center_mm, double initial_radius_mm, int max_iterations);
// The same with the radius held at radius_mm: only the centre moves.
SphereFit RefineSphereCenter(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                             const Eigen::Vector3d& initial_center_mm, double radius_mm, int max_iterations);

}  // namespace stereorig
