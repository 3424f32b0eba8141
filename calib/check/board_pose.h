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

// One corner's projection q = Project(cam_from_ref * ref_from_front(rt) *
// p_front) and, if `dq_drt` is given, d q / d rt (2x6; rt = ref_from_front's
// rotation vector (rad) and translation (mm)). Analytic: mrcal's d q / d
// p_cam chained with d (R(r) p) / d r from Ceres' Jets; it replaced central
// differences (13 poses and projections a corner and evaluation, two thirds
// of a nightly check's time; board_pose_test.cc holds it to them). False
// (q, dq_drt untouched) where the corner is behind the camera.
bool ProjectBoardCorner(const Camera& camera, const Pose& cam_from_ref, const double* rt,
                        const Eigen::Vector3d& p_front, Eigen::Vector2d* q, Eigen::Matrix<double, 2, 6>* dq_drt);

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
// quadratic form in a 6-D Gaussian:
//   mean = tr(A Sigma),  variance = 2 tr((A Sigma)^2).
// All corners share one pose error, so this variance is far larger than that
// of independent per-corner errors. The sources add in the pose, not in the
// sum: two of them, each alone a variance v, give a sum of variance 4 v, not
// 2 v (the cross term 4 tr(A Sigma_1 A Sigma_2)). Jacobians are numeric
// (central differences on the pose's rotation vector and translation).
struct PredictionStatistics {
  double mean_ss_px2 = 0;
  double var_ss_px4 = 0;
};
PredictionStatistics PredictionErrorStatistics(const Rig& rig, const Target& target,
                                               const std::vector<const BoardObservation*>& pose_views,
                                               const std::vector<std::vector<double>>& sigma_px_sources,
                                               const BoardObservation& view, const Pose& ref_from_front);

// The mean and variance of sum_k |e_k + J_k delta|^2 over the `num_corners`
// corners of a view: e_k each axis independent noise of variance
// noise_px^2, delta the error of the pose it is predicted through
// (`pose`, independent of e):
//   mean = 2 n noise^2 + tr(A Sigma),
//   variance = 4 n noise^4 + 4 noise^2 tr(A Sigma) + 2 tr((A Sigma)^2).
PredictionStatistics ViewPredictionStatistics(int num_corners, double noise_px, const PredictionStatistics& pose);

// A face's corner in the front-face frame.
Eigen::Vector3d CornerInFront(const Target& target, Face face, int id);

}  // namespace stereorig
