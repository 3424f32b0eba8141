// Stage 2: a module's stereo extrinsics, right_from_left, from the views its
// two cameras share, as one joint mrcal solve.
//
// Seeded with stage 1's intrinsics and board poses, mrcal solves both lenses,
// right_from_left and every board pose the module saw together (left camera
// at the reference). The report gives the baseline, the rotation and the
// rectified-row error: after rectifying the pair with the solved geometry,
// the row difference of each corner both cameras saw (px) - the epipolar
// error as a user of the rectified images meets it.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "calib/intrinsics.h"

namespace stereorig {

struct StereoOptions {
  int min_shared_views = 3;  // fewer views seen by both cameras is an input error; default 3
  bool verbose = false;      // mrcal's solver output; default false
  void Check() const;
};

struct StereoReport {
  int module = -1;
  std::string module_name;
  int num_shared_views = 0;  // captures both cameras saw (the same face) in the joint solve
  // Captures in which the two cameras saw different faces (the board's plane
  // between them, or a face misread): set aside here and in stage 3.
  std::vector<int> different_face_captures;
  int num_frames = 0;   // captures either camera saw
  double rms_px = 0.0;  // joint solve, RMS of residual coordinates
  int num_outliers = 0;
  double baseline_mm = 0.0;   // |t| of right_from_left
  double rotation_deg = 0.0;  // angle of right_from_left
  Eigen::Vector3d right_from_left_rotation_vector_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d right_from_left_translation_mm = Eigen::Vector3d::Zero();
  // 1 sigma of the above from the joint solve's covariance (mrcal's J'J,
  // scaled by the observed corner noise); NaN if the covariance failed
  // (covariance_status says why; the report writes null, the summary "no
  // sigma").
  std::string covariance_status = "not computed";  // "ok" or why the covariance failed
  double baseline_sigma_mm = 0.0;
  double rotation_sigma_deg = 0.0;
  Eigen::Vector3d right_from_left_rotation_vector_sigma_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d right_from_left_translation_sigma_mm = Eigen::Vector3d::Zero();
  double rectified_row_rms_px = 0.0;  // over corners both cameras saw
  double rectified_row_max_px = 0.0;
  int num_corner_pairs = 0;
  // Views left out of the joint solve, (capture, global camera index):
  // outlier rejection left them too few corners to fix a board pose (a
  // capture whose left and right images were swapped). Calibrate warns of
  // them (capture_folder.h).
  std::vector<std::pair<int, int>> views_left_out = {};
  // The board's tilt in each of those views as stage 1 solved it (TiltDeg;
  // NaN where stage 1 had no pose): a board seen nearly edge-on is left out
  // for its foreshortened corners, not for being another camera's image.
  std::vector<double> views_left_out_tilt_deg = {};
  IntrinsicsReport left, right;  // per-camera figures of the joint solve (uncertainty, coverage)
  // Cov(left's intrinsics, right's) of the joint solve, (N * N,) row-major,
  // rows the left's, as left/right.intrinsics_covariance (the
  // regularisation as a prior); empty if the covariance failed. Stage 3's
  // prior on the terms it cannot determine alone is joint over the pair.
  std::vector<double> intrinsics_cross_covariance = {};
};

struct StereoResult {
  Camera left, right;
  Pose right_from_left;
  std::vector<int> captures;         // (Nframes,) captures in the joint solve
  std::vector<Face> faces;           // (Nframes,)
  std::vector<Pose> left_from_face;  // (Nframes,) board poses in the module (= left camera) frame
  StereoReport report;
  MrcalProblem problem;
};

StereoResult CalibrateStereo(int module, const ModuleLayout& layout, const IntrinsicsResult& left,
                             const IntrinsicsResult& right, const std::vector<const BoardObservation*>& left_views,
                             const std::vector<const BoardObservation*>& right_views, const CalibrationInput& input,
                             const StereoOptions& options, const IntrinsicsOptions& iopt);

// Rectified-row differences (px) of corresponding pixels of a calibrated
// pair: both rays are turned into a common rectified frame whose x axis runs
// along the baseline, and projected with focal length `f_px`.
std::vector<double> RectifiedRowErrors(const Camera& left, const Camera& right, const Pose& right_from_left,
                                       const std::vector<Eigen::Vector2d>& q_left,
                                       const std::vector<Eigen::Vector2d>& q_right);

// Mean of rigid transforms (quaternion average, mean translation): a seed.
Pose AveragePoses(const std::vector<Pose>& poses);

}  // namespace stereorig
