// Stage 1: the intrinsics of one camera, solved with mrcal's C API.
//
// As mrcal-calibrate-cameras does: every board pose is seeded with PnP from a
// rough focal length (OpenCV), then mrcal solves in steps: the board poses
// alone, then with the lens core, then everything with the distortions under
// regularisation and with outlier rejection. The report carries the residual
// RMS, the worst views, the outliers, a coverage map and the projection
// uncertainty (a port of mrcal's, see projection_uncertainty.h).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "calib/core/camera.h"
#include "calib/core/pose.h"
#include "calib/mrcal_problem.h"
#include "calib/observations.h"

namespace stereorig {

struct IntrinsicsOptions {
  // Lens model as mrcal spells it: LENSMODEL_OPENCV4, 5, 8 or 12, or a
  // splined stereographic one such as
  // LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=50; not
  // LENSMODEL_PINHOLE (Check() says why).
  // Default LENSMODEL_OPENCV5: it holds a mild lens such as the default
  // rig's, and it is the richest model that needs no regularisation (see
  // LensmodelNeedsRegularization), so its fit and its sigma are unbiased.
  std::string lensmodel = "LENSMODEL_OPENCV5";
  double seed_focal_px = 0.0;    // rough focal length for the PnP seed, px; 0 (default): from the views' homographies
  int min_corners_per_view = 8;  // views with fewer corners are not used; default 8
  int min_views = 5;             // fewer usable views or distinct board poses is an input error; default 5
  double min_tilt_deg = 10.0;    // if no view tilts the board more than this, the set is degenerate; default 10 deg
  // A solve whose RMS is over this did not converge: stage 1 tries the next
  // seed candidate (calib/pinhole_seed.h), and calibrate writes no rig file
  // while any stage is over it (calib/convergence.h). Default 1 px: at 200 mm
  // and the default rig's 1025 px focal length ~0.2 mm across the ray, twice
  // the runtime's whole error budget, and 5x the synthetic noise the tests
  // inject; a camera that converged shows its corners' noise (0.02 px on the
  // rendered default dataset).
  double max_rms_px = 1.0;
  // Range of the points whose projection uncertainty is reported, mm. 0
  // (default): the median distance of the board from the camera in its
  // views, where the rig measures (a fixed 200 mm reported a rig working at
  // 300 mm ~3x too uncertain, and loosened its nightly check as much).
  double uncertainty_range_mm = 0;
  int coverage_cells_x = 8;      // coverage map columns; default 8
  int coverage_cells_y = 6;      // coverage map rows; default 6
  int worst_views_reported = 3;  // default 3
  bool verbose = false;          // mrcal's solver output to stderr; default false
  void Check() const;            // throws InputError naming the bad option
};

struct ViewResidual {
  int capture = -1;
  double rms_px = 0.0;  // RMS of the view's inlier residual coordinates (x and y pooled), px
  int num_corners = 0;  // inliers
};

struct PixelUncertainty {
  std::string where;  // "centre", "top-left", ...
  Eigen::Vector2d q_px = Eigen::Vector2d::Zero();
  double rms_stdev_px = 0.0;  // 1 sigma, sqrt(trace(Var q) / 2)
  double worst_direction_stdev_px = 0.0;
};

struct IntrinsicsReport {
  int camera = -1;
  std::string camera_name;
  std::string lensmodel;
  int num_views = 0;               // used in the solve
  int num_views_dropped = 0;       // too few corners
  int num_corners = 0;             // inliers in the final solve
  int num_outliers = 0;            // corners rejected by the solver
  double rms_px = 0.0;             // RMS of the inlier residual coordinates (x and y pooled), px
  double observed_sigma_px = 0.0;  // std of the residuals (the noise the uncertainty assumes)
  double max_tilt_deg = 0.0;       // largest board tilt among the views
  // Seed candidates solved from (calib/pinhole_seed.h): 1 where the first
  // converged; all of them where none did.
  int seeds_tried = 0;
  std::vector<ViewResidual> worst_views;
  int coverage_cells_x = 0, coverage_cells_y = 0;
  std::vector<int> coverage;                  // (cells_y, cells_x) row-major: inlier corners per cell
  double coverage_fraction = 0.0;             // cells holding at least one corner
  std::vector<PixelUncertainty> uncertainty;  // centre and the four image corners
  double uncertainty_range_mm = 0.0;
  std::vector<double> intrinsics;        // (Nparams,) as solved, mrcal's order (fx fy cx cy k1 k2 p1 p2 k3 ...)
  std::vector<double> intrinsics_sigma;  // (Nparams,) their 1 sigma from the solve's covariance; empty if none
  // (Nparams * Nparams,) row-major, in the parameters' units; empty if none:
  // their covariance with mrcal's regularisation taken as a Gaussian prior
  // (ProjectionUncertaintyEvaluator::Covariance, regularisation_as_prior;
  // without regularisation intrinsics_sigma's). Stage 3 refines the
  // parameters it cannot determine alone under their block of it
  // (calib/system.h, ModuleCameras).
  std::vector<double> intrinsics_covariance;
  // Captures whose views repeat one board pose (BoardPoseGroups), one group
  // per pose seen more than once, its captures ascending: repeated frames,
  // or the board left still. Each still counts as a view, and the solve
  // takes their corners as independent, its sigmas shrinking as if the pose
  // had been seen afresh; calibrate warns of them (capture_folder.h).
  std::vector<std::vector<int>> repeated_pose_captures{};
};

struct IntrinsicsResult {
  Camera camera;
  std::vector<int> captures;        // (Nviews,) the capture of each view used
  std::vector<Face> faces;          // (Nviews,)
  std::vector<Pose> cam_from_face;  // (Nviews,) solved board poses
  IntrinsicsReport report;
  MrcalProblem problem;  // the solved problem (for uncertainty and cross-checks)
};

// `views`: this camera's observations (all of the same camera). Throws
// InputError (`where` names the input) on too few views or a degenerate set.
// Solved from the first of RankedPinholeSeeds (calib/pinhole_seed.h); where
// that solve's RMS is over options.max_rms_px, from every candidate, the
// lowest RMS kept (`progress`, if given, is told so: that takes seconds).
// capture_names (capture index -> its folder's name, CalibrationInput's):
// how a refusal names the captures, by index where it has none.
IntrinsicsResult CalibrateIntrinsics(int camera, const CameraImager& spec, const TargetGeometry& target,
                                     const std::vector<const BoardObservation*>& views,
                                     const IntrinsicsOptions& options, const std::string& where,
                                     const std::function<void(const std::string&)>& progress = {},
                                     const std::map<int, std::string>& capture_names = {});

// The views of one camera grouped by board pose: two views show one pose if
// they saw the same face and the corners both saw (at least 4) differ by
// their noise alone: the difference, less its smooth part over the board
// (a quadratic in the grid position, `corners_x` a row's corners: how a
// moved board's corners move), measures the noise, and the whole is within
// 1.5 x that (intrinsics.cc, DifferenceIsNoise, says why); or within 0.005
// px RMS (one frame again), and never beyond `max_same_pose_rms_px` RMS (x
// and y pooled). Returns the groups in the order of their first view, each
// group's indices into `views` ascending. Stage 1 counts the groups, not
// the views, against IntrinsicsOptions::min_views.
std::vector<std::vector<int>> BoardPoseGroups(const std::vector<const BoardObservation*>& views, int corners_x,
                                              double max_same_pose_rms_px);
// The most two views of one pose may differ: two detections of a board that
// did not move differ only by the corners' noise, sqrt(2) sigma per
// coordinate, and a calibration accepts corners whose noise is up to
// `max_rms_px` (IntrinsicsOptions::max_rms_px), so sqrt(2) x max_rms_px. A
// ceiling only: alone, it merged distinct tilts of a small board
// (BoardPoseGroups measures the noise itself).
double SamePoseRmsPx(double max_rms_px);

// Shared helpers for the mrcal problems of stages 1 and 2.
// An empty problem of `num_cameras` cameras of `lensmodel` (mrcal's name,
// IntrinsicsOptions::Check passed) observing `target`'s board.
MrcalProblem BoardProblem(const std::string& lensmodel, const TargetGeometry& target, int num_cameras);
// False for the lens models whose every parameter the boards determine
// (PINHOLE, which IntrinsicsOptions::Check refuses to calibrate, OPENCV4,
// OPENCV5): their final solve runs without
// regularisation, so the result is the plain least-squares optimum (as
// OpenCV's) and its covariance has no regularisation bias. True for the
// others: a spline's knots outside the observed region, and the rational
// k4..k6 of OPENCV8/12 (which trade off with k1..k3 over a lens's field),
// are otherwise undetermined; measured on the default rig, an unregularised
// OPENCV8 gave NaN uncertainties and 1e6-sigma S errors.
bool LensmodelNeedsRegularization(const std::string& lensmodel);
// The last step of a staged mrcal solve: everything selected for
// optimisation is solved with the distortions regularised and outliers
// rejected; then, for a model that does not need the regularisation, once
// more without it (the outliers found stay out). Returns the number of pool
// entries with weight <= 0 afterwards (missing corners + outliers).
int SolveFinal(MrcalProblem* problem, bool verbose);
// The board's tilt in a view: the angle between the board's normal and the
// camera's optical axis, degrees (0: fronto-parallel). Stage 1 refuses views
// of which none tilts more than IntrinsicsOptions::min_tilt_deg: as posed
// from the pinhole seed, and as solved with the focal length 3 sigma lower
// (intrinsics.cc: SolvedTiltLowerBoundDeg).
double TiltDeg(const Pose& cam_from_face);
// True if the corners span at least two rows and two columns of the board
// (not all collinear), so that a board pose follows from them.
bool CornersSpanAPlane(const std::vector<int>& corner_ids, int corners_x);
// Fills one observation's (corners_y, corners_x) pool block: seen corners
// with weight 1, the others with weight -1.
void FillPoolBlock(const BoardObservation& obs, const TargetGeometry& target, mrcal_point3_t* block);
// RMS of the inlier board residual coordinates (x and y pooled), px: directly
// comparable with a per-coordinate corner noise sigma.
double BoardResidualRms(const MrcalProblem& problem, const std::vector<double>& x);
// Reports for a solved problem: per-view residuals, coverage, uncertainty
// (projection, and the intrinsics' own 1 sigma).
std::vector<ViewResidual> ViewResiduals(const MrcalProblem& problem, const std::vector<double>& x,
                                        const std::vector<int>& view_capture, int icam_intrinsics);
void FillCoverageAndUncertainty(const MrcalProblem& problem, int icam_intrinsics, const IntrinsicsOptions& options,
                                int width_px, int height_px, IntrinsicsReport* report);

}  // namespace stereorig
