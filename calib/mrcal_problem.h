// A chessboard calibration problem in the layout mrcal's C API takes, and the
// calls on it: mrcal_optimize and mrcal_optimizer_callback.
//
// mrcal numbers things its own way: "intrinsics" cameras (lenses),
// "extrinsics" cameras (poses; camera 0 sits at the reference and has none),
// "frames" (board poses, frame -> reference). Every observation is a whole
// corners_y x corners_x grid; corners not seen carry weight -1, as
// mrcal-calibrate-cameras does for partial boards.
#pragma once

#include <string>
#include <vector>

#include "calib/core/mrcal_c.h"
#include "calib/core/pose.h"

namespace stereorig {

struct MrcalProblem {
  std::string lensmodel_name;  // as mrcal spells it
  mrcal_lensmodel_t lensmodel{};
  int corners_x = 0, corners_y = 0;  // board grid (width_n, height_n)
  double spacing_mm = 0.0;           // board pitch
  int num_intrinsics_cameras = 0;
  std::vector<double> intrinsics;                       // (Ncameras_intrinsics, Nparams)
  std::vector<int> imagersizes;                         // (Ncameras_intrinsics, 2)
  std::vector<mrcal_pose_t> extrinsics_fromref;         // (Ncameras_extrinsics,) rt_cam_ref
  std::vector<mrcal_pose_t> frames_toref;               // (Nframes,) rt_ref_frame
  std::vector<mrcal_observation_board_t> observations;  // (Nobservations,)
  std::vector<mrcal_point3_t> pool;                     // (Nobservations, corners_y, corners_x): x, y, weight
  mrcal_problem_selections_t selections{};

  // Sets the lens model; returns false if mrcal does not know the name.
  bool SetLensmodel(const std::string& name);
  int num_params() const { return mrcal_lensmodel_num_params(&lensmodel); }
  int num_frames() const { return static_cast<int>(frames_toref.size()); }
  int num_extrinsics() const { return static_cast<int>(extrinsics_fromref.size()); }
  int num_observations() const { return static_cast<int>(observations.size()); }
  int num_states() const;
  int num_measurements() const;
  int num_measurements_boards() const;

  // The staged solve's first step, as mrcal's own tool begins: the board
  // poses and camera extrinsics alone, lens held, no regularisation, no
  // outlier rejection. Sets `selections` to that.
  void SelectPosesOnly();
  // Runs mrcal_optimize with the current selections. Updates the state and
  // marks new outliers in the pool (weight < 0). Unless `verbose`, mrcal's
  // outlier-loop lines are kept off stderr (their total counts the unseen
  // corners too); its other lines pass.
  mrcal_stats_t Optimize(bool verbose = false);
  // Residuals x (Nmeasurements,) at the current state (board ones first:
  // (Nobservations, corners_y, corners_x, 2), weighted, 0 for outliers).
  std::vector<double> Residuals() const;
  // Number of pool entries with weight <= 0 (missing + outliers).
  int CountNonPositiveWeights() const;

  // The median distance, mm, from intrinsics camera `icam_intrinsics` to
  // the centre of the board's corner grid over that camera's observations,
  // at the current poses: where the board was held, which is where the rig
  // is meant to measure. 0 if the camera observes nothing.
  double MedianBoardDistanceMm(int icam_intrinsics) const;

  // Pose helpers. mrcal_pose_t is (r: rotation vector, t: mm).
  static mrcal_pose_t ToMrcal(const Pose& a_from_b);
  static Pose FromMrcal(const mrcal_pose_t& rt_a_b);
};

}  // namespace stereorig
