// The target's pose from any set of calibrated cameras with the calibration
// held fixed: ref_from_front, the board's front-face frame in the rig's
// reference frame. Back-face corners enter through back_from_front.
#pragma once

#include <vector>

#include "calib/core/rig.h"
#include "calib/observations.h"
#include "targets/target.h"

namespace stereorig {

struct BoardPoseEstimate {
  bool ok = false;
  Pose ref_from_front;
  double rms_px = 0;  // per axis (as mrcal reports), over every corner of the views used
  int num_corners = 0;
};

// `views` are all of one capture. Seeds with `seed` if given, else with PnP
// from the view with the most corners, then minimises reprojection error over
// every view (Ceres). A pose from one camera alone has a near-mirror twin;
// seeding it from all cameras of the capture avoids converging there.
BoardPoseEstimate EstimateBoardPose(const Rig& rig, const Target& target,
                                    const std::vector<const BoardObservation*>& views, const Pose* seed = nullptr);

// Reprojection residuals q_predicted - q (px, per corner) of `view` for a
// given board pose.
std::vector<Eigen::Vector2d> ReprojectionErrors(const Rig& rig, const Target& target, const BoardObservation& view,
                                                const Pose& ref_from_front);

// The linearised covariance of a board pose estimated from `pose_views`,
// each corner with its camera's per-axis noise sigma_px[camera]: the inverse
// of sum_k J_k^T J_k / sigma^2 (J_k the 2x6 Jacobian of corner k's pixel by
// the pose's rotation vector, rad, and translation, mm, of ref_from_front).
Eigen::Matrix<double, 6, 6> BoardPoseCovariance(const Rig& rig, const Target& target,
                                                const std::vector<const BoardObservation*>& pose_views,
                                                const std::vector<double>& sigma_px, const Pose& ref_from_front);

// Linearised statistics of the prediction error that a pose's own
// uncertainty puts on the corners of `view`. The pose errs by independent
// sources (tonight's corner noise, the calibration's own error), each a
// per-camera noise sigma_px[camera] on the corners of `pose_views`: its
// covariance Sigma is the sum of each source's (BoardPoseCovariance). With
// J_k the 2x6 Jacobian of corner k's pixel by the pose and A = sum_k J_k^T
// J_k, the sum over the view's corners of |prediction error|^2 is a
// quadratic form in a 6-D Gaussian, sum_i mu_i chi2_1 with mu_i the
// eigenvalues of A Sigma:
//   mean = tr(A Sigma),  variance = 2 tr((A Sigma)^2),
//   third cumulant = 8 tr((A Sigma)^3).
// All corners share one pose error, so this variance is far larger than that
// of independent per-corner errors, and the sum is skewed as a chi-square of
// few degrees of freedom is. The sources add in the pose, not in the sum:
// two of them, each a variance v, give a sum of variance 4 v, not 2 v.
// Jacobians are numeric (central differences on the pose's rotation vector
// and translation).
struct PredictionStatistics {
  double mean_ss_px2 = 0;
  double var_ss_px4 = 0;
  double third_ss_px6 = 0;  // third cumulant
};
PredictionStatistics PredictionErrorStatistics(const Rig& rig, const Target& target,
                                               const std::vector<const BoardObservation*>& pose_views,
                                               const std::vector<std::vector<double>>& sigma_px_sources,
                                               const BoardObservation& view, const Pose& ref_from_front);

// The cumulants of a sum of squares of Gaussians (px^2, its mean, variance
// and third cumulant; those of independent sums add), and the value it
// exceeds with the one-sided tail probability of a Gaussian z-score. A sum
// that one shared pose error dominates is skewed: mean + z standard
// deviations is exceeded far more often than the Gaussian tail says (a
// chi-square of 2 degrees of freedom: 3.5 standard deviations above its
// mean with probability 1.1e-2, not 2.3e-4). The quantile matches the three
// cumulants with a shifted and scaled chi-square of h = 8 k2^3 / k3^2
// degrees of freedom (Pearson's approximation for quadratic forms), its
// quantile by Wilson-Hilferty; with no skew, mean + z standard deviations.
struct SumOfSquaresCumulants {
  double mean_px2 = 0;
  double var_px4 = 0;
  double third_px6 = 0;
  void Add(const SumOfSquaresCumulants& o) { mean_px2 += o.mean_px2, var_px4 += o.var_px4, third_px6 += o.third_px6; }
  double UpperQuantilePx2(double z) const;
};

// The cumulants of sum_k |e_k + J_k delta|^2 over `num_corners` corners:
// e_k each axis independent noise of variance noise_px^2, delta the pose
// error of `pose` (independent of e). Its covariance's eigenvalues are
// noise^2 + mu_i (the 6 of A Sigma) and noise^2 (2 n - 6 times).
SumOfSquaresCumulants ViewPredictionCumulants(int num_corners, double noise_px, const PredictionStatistics& pose);

// A face's corner in the front-face frame.
Eigen::Vector3d CornerInFront(const Target& target, Face face, int id);

}  // namespace stereorig
