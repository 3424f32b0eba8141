// What a fitted shape model misses, as a smooth field over the surface, so
// that hole filling can follow a real object (a tuber's bumps) instead of
// the ideal ellipsoid: the measured points' signed distances to the model
// ("residuals", along the model's normal) are interpolated by a Gaussian
// process (simple kriging) with zero mean, a squared-exponential kernel of
// 3D distance,
//
//   cov(r(x), r(x')) = s^2 exp(-|x - x'|^2 / (2 l^2)),  plus noise n^2 on the diagonal,
//
// and the posterior mean is predicted at any point on the model. Far from
// the data (more than ~2 l) the prediction decays to 0: the model itself.
//
// Fitting, all deterministic:
// - residuals further than outlier_mads robust sigmas (1.4826 MAD) from
//   their median are dropped (gross mismatches, a cup's floor);
// - if the rms of the rest is below min_rms_mm the model is exact to the
//   noise (a sphere, a cup) and the field is off: Predict() returns 0;
// - the data are reduced to cell means: the mean point and mean residual
//   of each occupied cube of a grid whose edge is grown until at most
//   max_points cubes remain. That spreads the points evenly over the seen
//   surface (its edges carry the extrapolation into the holes; a stride
//   through the cloud's rows thinned them: tuber fill 0.19 vs 0.09 mm mean)
//   and averages the noise down. A cell mean's noise variance is taken
//   inversely proportional to its point count (a sparse cell at the seen
//   region's edge, where the points are noisiest, must not steer the
//   extrapolation: with equal weights the tuber's fill beyond 15 mm from
//   the data moved by up to 0.2 mm with the cell size);
// - the length scale l (unless given) and the noise ratio n^2 / s^2 of a
//   cell mean of the median count are chosen by the log marginal likelihood, with s^2 profiled
//   out (s^2 = y' (C + ratio I)^-1 y / N, C the unit-variance kernel
//   matrix), over candidate_lengths_mm x candidate_noise_ratios on a
//   coarser set of max_likelihood_points cell means: the noise variance
//   comes from the data;
// - the field is then fitted (Eigen LLT) on the max_points cell means: with
//   l >= 6 mm that is dense enough (~3 mm apart on a tuber's seen surface)
//   and keeps the Cholesky at O(max_points^3).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

struct ResidualFieldOptions {
  double length_mm = 0;  // kernel length scale; 0 (default) = chosen by marginal likelihood
  std::vector<double> candidate_lengths_mm = {6, 8.5, 12, 17, 24, 30};         // default: 6-30 mm, x1.4 steps
  std::vector<double> candidate_noise_ratios = {0.003, 0.01, 0.03, 0.1, 0.3};  // n^2 / s^2
  int max_points = 1000;            // cell means the field is fitted on (at most); default 1000
  int max_likelihood_points = 400;  // cell means the hyperparameters are chosen on; default 400
  double min_rms_mm = 0.1;          // residual rms below which the field is off; default 0.1 mm
  double outlier_mads = 5;          // residual cut, in robust sigmas about the median; default 5
};

class ResidualField {
 public:
  ResidualField() = default;  // off: predicts 0

  // points_mm: (N) where each residual was taken (best: its foot on the
  // model surface); residuals_mm: (N) signed distances to the model along
  // its outward normal (> 0 outside).
  static ResidualField Fit(const std::vector<Eigen::Vector3d>& points_mm, const std::vector<double>& residuals_mm,
                           const ResidualFieldOptions& options);

  // The field's posterior mean at p, mm (0 when off). Thread-safe (const).
  double Predict(const Eigen::Vector3d& p_mm) const;

  bool active() const { return alpha_.size() > 0; }
  double length_mm() const { return length_mm_; }
  double signal_sd_mm() const { return signal_sd_mm_; }
  double noise_sd_mm() const { return noise_sd_mm_; }  // of a cell mean of the median count
  double residual_rms_mm() const { return residual_rms_mm_; }
  // One line: the hyperparameters, or why the field is off.
  const std::string& description() const { return description_; }

 private:
  Eigen::Matrix3Xd points_mm_;  // (3, M) the fit's points
  Eigen::VectorXd alpha_;       // (M) (C + ratio W^-1)^-1 y, W the cells' weights
  double length_mm_ = 0, signal_sd_mm_ = 0, noise_sd_mm_ = 0, residual_rms_mm_ = 0;
  std::string description_ = "residual field off";
};

}  // namespace stereorig
