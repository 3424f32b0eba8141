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
// - for each candidate length l, the noise ratio n^2 / s^2 of a cell mean
//   of the median count is chosen by the log marginal likelihood, with s^2
//   profiled out (s^2 = y' (C + ratio I)^-1 y / N, C the unit-variance
//   kernel matrix), on a coarser set of max_likelihood_points cell means:
//   the noise variance comes from the data;
// - the length l (unless given) is the candidate whose field best predicts
//   the data it was not given, a cube of cv_block_mm at a time (leave one
//   block out, all blocks in turn: the exact held-out residuals of a
//   Gaussian process, e_B = ((A^-1)_BB)^-1 (A^-1 y)_B, A = C + ratio W^-1,
//   so one inverse per length). That is what hole filling asks of the
//   field: to carry the seen surface a few millimetres into what was not
//   seen. The marginal likelihood instead scores how well the field explains
//   the data it has; on the simulator's tubers it was nearly flat between 12
//   and 17 mm (log-likelihoods 1277.05 and 1276.61 on the demo's) and took
//   12 on two realizations of four, where the fill 5-15 mm from the data
//   then strayed past 0.5 mm (demo: 92.8 % within 0.5 mm, mean 0.179 mm);
//   the held-out error prefers 17 or 24 on all four, by 20-50 %, with
//   blocks of 10, 15 or 20 mm alike (demo: 100 %, mean 0.121 mm;
//   docs/reconstruct-log.md, session 18);
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
  // The held-out blocks' edge for choosing the length, mm; default 15 (the
  // fill's bands reach 5-15 mm from the data). 0 = choose the length by the
  // marginal likelihood too (before session 18), as also happens when all
  // the data lie in one block.
  double cv_block_mm = 15;
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

namespace internal {

// How badly the field of unit-variance kernel matrix c (of the points x)
// and noise ratio predicts each block of the data y from the others: the
// sum over every cube of block_mm (grid anchored at the origin) of the
// weighted squared held-out residuals. Exact for a Gaussian process: the
// residuals of block B left out are ((A^-1)_BB)^-1 (A^-1 y)_B, with
// A = c + ratio W^-1 (W = weights). +inf if A is not positive definite.
double BlockCrossValidationError(const Eigen::MatrixXd& c, double ratio, const Eigen::VectorXd& weights,
                                 const Eigen::VectorXd& y, const Eigen::Matrix3Xd& x, double block_mm);

}  // namespace internal

}  // namespace stereorig
