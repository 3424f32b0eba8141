// Stage 3: the system, i.e. where every module sits in the reference frame
// (module 0), giving the S matrix.
//
//  1. In each capture, each module triangulates the corners its two cameras
//     both saw (in its own frame) and finds the board's pose by Horn's
//     absolute orientation; a back face is mapped to the front face's frame
//     through the target's back_from_front.
//  2. For every pair of modules that saw the same captures, Horn's absolute
//     orientation on the triangulated corners of each module, expressed in the
//     other module through the other's board pose, gives
//     module_i_from_module_j. A maximum spanning tree (by shared captures)
//     from module 0 chains them: module0_from_module_k.
//  3. One Ceres bundle adjustment over every capture and camera minimises the
//     reprojection error with a robust (Huber) loss. Parameters: S (each
//     module's pose in the reference), every board pose, optionally the
//     stereo extrinsics and the intrinsics, and back_from_front under its
//     measured prior. ceres::Covariance gives the 1 sigma of S and of the
//     refined right_from_left and intrinsics (those the rig file holds).
#pragma once

#include <ceres/covariance.h>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "calib/core/camera.h"
#include "calib/core/pose.h"
#include "calib/observations.h"
#include "calib/plate_difference.h"

namespace stereorig {

struct SystemOptions {
  double huber_px = 1.0;      // Huber loss scale, px; default 1
  bool refine_stereo = true;  // free each module's right_from_left in the adjustment; default true
  // Free every camera's intrinsics: the core and OPENCV's k1..k3, p1, p2
  // outright; OPENCV8/12's k4..k6, s1..s4 and a spline's knots, which need
  // mrcal's regularisation (Stage3HeldIntrinsics), under stage 2's
  // covariance of them as a prior (ModuleCameras).
  // With them free, the covariance of S includes the lens uncertainty, which
  // moves each module's frame (a calibrated camera's frame trades rotation
  // against its centre). Default true.
  bool refine_intrinsics = true;
  bool refine_back_from_front = true;  // free back_from_front under its prior; default true
  int min_triangulated_corners = 6;    // a module's board pose needs this many corners both cameras saw; default 6
  int max_iterations = 100;            // Ceres; default 100
  bool compute_covariance = true;      // 1 sigma of S, refined stereo and intrinsics; default true
  void Check() const;
};

// One module's calibrated stereo pair (from stage 2).
struct ModuleCameras {
  int left_camera = -1, right_camera = -1;  // global indices
  Camera left, right;
  Pose right_from_left;
  // Stage 2's covariance of each camera's intrinsics ((N * N,) row-major,
  // IntrinsicsReport::intrinsics_covariance): the Gaussian prior under which
  // stage 3 refines those it cannot determine alone (Stage3HeldIntrinsics).
  // Empty: none; they are held at their values, and S's 1 sigma is
  // conditional on them (SystemReport::sigma_conditional_on).
  std::vector<double> left_intrinsics_covariance = {}, right_intrinsics_covariance = {};
  // Stage 2's Cov(left's intrinsics, right's) ((N * N,) row-major, rows the
  // left's; StereoReport::intrinsics_cross_covariance): with it the prior is
  // joint over the pair. Empty: the two taken as independent.
  std::vector<double> left_right_intrinsics_covariance = {};
};

// The earlier stages' verdicts that stage 3 honours: the views stage 1
// dropped (their inliers no longer determined a board pose, or too few
// corners), the corners mrcal's outlier rejection flagged in stage 1 (the
// camera's own solve) or stage 2 (the module's joint solve), and the captures
// stage 2 set aside for a module because its two cameras saw different faces
// (StereoReport::different_face_captures: stage 2's list, not recomputed
// here). They stay out of the triangulated board poses and of the
// adjustment: its Huber loss only bounds an outlier's pull, it does not
// remove it.
struct SystemExclusions {
  std::set<std::pair<int, int>> views;            // (capture, camera)
  std::set<std::tuple<int, int, int>> corners;    // (capture, camera, corner id)
  std::set<std::pair<int, int>> module_captures;  // (capture, module): both of the module's views
  bool ExcludesView(int capture, int camera) const { return views.count({capture, camera}) > 0; }
  bool ExcludesCorner(int capture, int camera, int id) const { return corners.count({capture, camera, id}) > 0; }
  bool ExcludesModuleCapture(int capture, int module) const { return module_captures.count({capture, module}) > 0; }
};

struct STransformSigma {
  int module = -1;                                         // S[0][module] = module0_from_module
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // 1 sigma of a rotation about the reference's x, y, z
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
};

// 1 sigma of one module's refined right_from_left (present when it was free).
struct RefinedStereoSigma {
  int module = -1;
  double baseline_mm = 0, baseline_sigma_mm = 0;                  // |t| and its 1 sigma
  double rotation_deg = 0, rotation_sigma_deg = 0;                // |r| and its 1 sigma
  Eigen::Vector3d rotation_vector_deg = Eigen::Vector3d::Zero();  // r of right_from_left, and per-component sigma
  Eigen::Vector3d rotation_vector_sigma_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();  // t of right_from_left, and per-component sigma
  Eigen::Vector3d translation_sigma_mm = Eigen::Vector3d::Zero();
};

// 1 sigma of one camera's refined intrinsics (present when they were free).
struct RefinedIntrinsicsSigma {
  int camera = -1;                 // global index
  std::vector<double> intrinsics;  // (Nintrinsics,) as refined, mrcal's order
  std::vector<double> sigma;       // (Nintrinsics,) 1 sigma; 0 for a parameter held at its stage-2 value (no prior)
};

struct SystemReport {
  int num_captures = 0;                                // captures seen by at least one module with a board pose
  std::map<std::pair<int, int>, int> shared_captures;  // (i, j) -> captures both modules posed
  std::vector<std::pair<int, int>> spanning_tree;      // (parent, child) edges used for Horn
  std::map<std::pair<int, int>, double> horn_rms_mm;   // Horn fit RMS of each tree edge
  double horn_reprojection_rms_px = 0.0;               // S and stereo held at Horn/stage 2, board poses solved
  // "" if that Horn-only solve ended at Ceres's CONVERGENCE and its
  // residuals were evaluated; else how it ended (its iteration limit, a
  // failure: horn_only_stopped_short) and/or that its residuals could not be
  // evaluated (horn_reprojection_rms_px NaN). Not a refusal: it only seeds
  // the full adjustment (judged by solver_problem), but
  // horn_reprojection_rms_px is then where it stopped, or not a number
  // (Calibrate warns of it: HornOnlyWarning).
  std::string horn_only_solver_problem;
  bool horn_only_stopped_short = false;
  double refined_reprojection_rms_px = 0.0;  // after the full adjustment
  // The median of the corners' residual distances after it, px: what the
  // convergence check reads (calib/convergence.h), as the RMS counts in full
  // the few corners the Huber loss leaves out by design.
  double refined_median_corner_residual_px = 0.0;
  int num_residual_corners = 0;
  // Each capture's RMS over its corners' residual coordinates after the
  // adjustment (as refined_reprojection_rms_px over all), worst first: the
  // convergence check names the captures that raise stage 3's RMS.
  struct CaptureRms {
    int capture = 0;
    double rms_px = 0.0;
    int corners = 0;
  };
  std::vector<CaptureRms> refined_capture_rms;
  // Each camera's corners after the adjustment: their residual distances
  // hypot(du, dv), px, by median and 90th percentile, and the RMS over their
  // coordinates. In camera order. The convergence check holds each camera
  // to them (calib/convergence.h), so that one module's corners are not
  // diluted among the others'.
  struct CameraResiduals {
    int camera = -1;  // global index
    int corners = 0;
    double rms_px = 0.0;
    double median_px = 0.0;
    double p90_px = 0.0;
  };
  std::vector<CameraResiduals> refined_camera_residuals;
  // Left out as the earlier stages judged (SystemExclusions), counted among
  // the views and corners the adjustment would otherwise have used:
  int num_skipped_views = 0;                             // views stage 1 or 2 dropped
  int num_skipped_view_corners = 0;                      // their corners
  int num_skipped_outlier_corners = 0;                   // single corners stage 1 or 2 flagged as outliers
  std::vector<Pose> module0_from_module_horn;            // (M,)
  std::vector<Pose> module0_from_module;                 // (M,) refined
  std::vector<STransformSigma> sigma;                    // for modules 1..M-1
  std::vector<RefinedStereoSigma> stereo_sigma;          // (M,) when refine_stereo, else empty
  std::vector<RefinedIntrinsicsSigma> intrinsics_sigma;  // (cameras,) when refine_intrinsics, else empty
  std::string covariance_status;                         // "ok" or why it is missing
  // "" if the 1 sigma of S holds every intrinsic's uncertainty; else which
  // intrinsics stage 3 held constant, on whose values S's 1 sigma is
  // conditional (their own uncertainty is not in it): all of them with
  // refine_intrinsics false, or those of Stage3HeldIntrinsics for a camera
  // without stage 2's covariance of them.
  std::string sigma_conditional_on;
  // "" if the adjustment converged; else why not (Ceres stopped short of
  // convergence, or the residuals could not be evaluated), for the
  // convergence check (calib/convergence.h), which then refuses the rig.
  std::string solver_problem;
  // The iteration limit its two solves were given (SystemOptions::
  // max_iterations), and whether the full adjustment stopped at it (Ceres's
  // NO_CONVERGENCE): the refusal then names the limit and how to raise it.
  int max_iterations = 0;
  bool solver_at_iteration_limit = false;
  Pose back_from_front;                     // as refined
  double back_from_front_change_deg = 0.0;  // refined vs measured
  double back_from_front_change_mm = 0.0;
  // The refined back_from_front against the target file's, per axis over the
  // file's stated sigma (calib/plate_difference.h). The refined value is the
  // file's (the prior) updated by the corners, so for a file that is right
  // it moves by less than the prior's spread: chi-square at most as wide as
  // chi-square with as many degrees of freedom as axes refined (axes; an
  // axis whose sigma is 0 is held and not judged). Zero where it was held
  // whole (every sigma 0, no back face seen, or refine_back_from_front
  // false).
  PlateDifference back_from_front_vs_file;
  std::string solver_summary;  // Ceres BriefReport
};

struct SystemResult {
  std::vector<Pose> module0_from_module;       // (M,) refined; [0] = identity
  std::vector<Pose> module0_from_module_horn;  // (M,)
  std::vector<ModuleCameras> modules;          // refined stereo/intrinsics (unchanged if not refined)
  SystemReport report;
};

// `modules`: stage-2 results per module. `corner_sigma_px`: the corner noise
// (stage 2's residual RMS), which weighs back_from_front's prior against the
// reprojection residuals. Throws InputError if a module shares no capture
// with the others (the S matrix would be undetermined). `excluded`: views,
// corners and module-captures the earlier stages rejected or set aside, left
// out here too (Calibrate passes them). No default: a caller passing none
// gets every view in the adjustment, those of a capture whose two views of
// a module show different faces included (such a capture gives that module
// no board pose of its own, but its corners still enter wherever another
// module posed the board).
SystemResult CalibrateSystem(const CalibrationInput& input, const std::vector<ModuleCameras>& modules,
                             double corner_sigma_px, const SystemOptions& options, const SystemExclusions& excluded);

// The intrinsics (indices in mrcal's order) stage 3 cannot determine
// alone, for a camera of `lensmodel` with `num_intrinsics` parameters: none
// for a model whose every parameter the boards determine
// (!LensmodelNeedsRegularization: OPENCV4, OPENCV5); OPENCV8's and
// OPENCV12's k4..k6 and s1..s4 (index 9 on); everything but the core (fx,
// fy, cx, cy) for the others (a spline's knots). Ceres has none of mrcal's
// regularisation to tie them down: OPENCV12's, freed, drifted to a pole-zero
// pair inside the image (k1..k6 in the hundreds), Ceres stopped at its
// iteration limit and S moved 2.95 mm off the truth. Stage 3 refines them
// under stage 2's covariance of them (HeldIntrinsicsPrior), or holds them
// where it has none. Held with a covariance at hand, their own uncertainty
// was missing from S's: OPENCV12's S[0][1] on the demo dataset 0.30 deg /
// 1.67 mm from the truth against a 1 sigma of 0.005 deg / 0.02 mm (z up to
// 75), its principal points 4 px off against 0.05 px.
std::vector<int> Stage3HeldIntrinsics(const std::string& lensmodel, int num_intrinsics);

// How stage 3 computes its covariance from `num_free` tangent parameters:
// a problem that leaves a direction undetermined (a singular value of its
// Jacobian below sqrt(min_reciprocal_condition_number) of the largest) makes
// Compute fail. With null_space_rank = -1, Ceres dropped such directions
// and returned the pseudo-inverse, with no word: OPENCV12's cx sigma came out
// 0.0002-0.01 px where OPENCV5's, a subset of it, is 0.05 px.
ceres::Covariance::Options Stage3CovarianceOptions(int num_free);

// cov->Compute(pairs, problem) without Ceres's glog line on a rank-deficient
// J'J ("Covariance matrix is near rank deficient ..."): the false it returns
// says so already, in our words where it matters (calib/system.cc).
bool ComputeCovarianceQuietly(ceres::Covariance* cov, const std::vector<std::pair<const double*, const double*>>& pairs,
                              ceres::Problem* problem);

// Board poses: for each capture, module_from_front of one module, from its
// triangulated corners (Horn). Also the triangulated points themselves.
struct ModuleCaptureView {
  Face face = Face::kFront;
  Pose module_from_front;
  std::vector<int> corner_ids;            // (N,)
  std::vector<Eigen::Vector3d> p_module;  // (N,) triangulated, module frame, mm
};
// views[k][capture]: module k's posed captures, from the corners `excluded`
// leaves in.
std::vector<std::map<int, ModuleCaptureView>> PoseBoardsByTriangulation(const CalibrationInput& input,
                                                                        const std::vector<ModuleCameras>& modules,
                                                                        int min_corners,
                                                                        const SystemExclusions& excluded = {});

}  // namespace stereorig
