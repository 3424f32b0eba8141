// Projection uncertainty of a solved mrcal problem: a port of mrcal 2.2's
// Python `mrcal.projection_uncertainty` (model_analysis.py), which the C API
// lacks.
//
// The method ("mean-frames"): the noise on the observed corners (sigma, px,
// estimated as the standard deviation of the chessboard residuals, as mrcal
// does) propagates to the optimized state b through the linearised solve,
//   Var(b*) = sigma^2 inv(J*'J*) J*obs' J*obs inv(J*'J*)     (b* = packed state)
// and from b to the projection q of a point p_cam fixed in the space of the
// calibration boards: p_cam is mapped into every frame's coordinates, each
// frame maps it back to the reference, the results are averaged, and the mean
// is projected. dq/db therefore involves the intrinsics, the camera's
// extrinsics and every frame. J' is factorised with CHOLMOD, as mrcal does.
//
// The same covariance gives the 1 sigma of the solved parameters themselves
// (IntrinsicsCovariance, ExtrinsicsCovariance), or of any function of the
// state through its gradient (Covariance).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "calib/mrcal_problem.h"

namespace stereorig {

struct ProjectionUncertainty {
  Eigen::Matrix2d covariance_px2 = Eigen::Matrix2d::Zero();  // Var(q), px^2
  double rms_stdev_px = 0.0;                                 // sqrt(trace / 2): mrcal's 'rms-stdev'
  double worst_direction_stdev_px = 0.0;  // sqrt of the larger eigenvalue: mrcal's 'worstdirection-stdev'
};

// Gradients of k functions of the state, (k, Nstate), with respect to the
// unpacked state (mrcal's units: intrinsics as stored, rt in rad and mm).
using StateGradient = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

class ProjectionUncertaintyEvaluator {
 public:
  // Evaluates J at the problem's current (solved) state and factorises J'J.
  // `problem` must outlive this object and not change. ok() is false if the
  // factorisation failed (e.g. a frame nobody observes); message() says why.
  explicit ProjectionUncertaintyEvaluator(const MrcalProblem& problem);
  ~ProjectionUncertaintyEvaluator();
  ProjectionUncertaintyEvaluator(const ProjectionUncertaintyEvaluator&) = delete;
  ProjectionUncertaintyEvaluator& operator=(const ProjectionUncertaintyEvaluator&) = delete;

  bool ok() const;
  const std::string& message() const;
  // The noise assumed on every observed corner coordinate: the standard
  // deviation of the non-outlier chessboard residuals, px.
  double observed_pixel_sigma_px() const;

  // Uncertainty of projecting `p_cam` (mm, in the frame of intrinsics camera
  // `icam_intrinsics`) through that camera.
  ProjectionUncertainty AtPoint(int icam_intrinsics, const Eigen::Vector3d& p_cam) const;
  // The same for the point that the solved camera sees at pixel `q_px`, at
  // `range_mm` from the camera centre.
  ProjectionUncertainty AtPixel(int icam_intrinsics, const Eigen::Vector2d& q_px, double range_mm) const;

  // Var(y) (k, k) of y = f(state) with dy/db = `dy_db` (k, Nstate, unpacked),
  // scaled by the observed noise: sigma^2 dy_db inv(J'J) dy_db' without
  // regularisation, the sandwich above with it (the corners' noise alone).
  // `regularisation_as_prior`: sigma^2 dy_db inv(J'J) dy_db' with it too, J
  // holding its rows: the covariance of the posterior whose Gaussian prior
  // is the regularisation. Along a direction only the regularisation
  // determines, the sandwich's variance goes to 0 (the corners do not move
  // it), the posterior's to the prior's: what stage 3 refines OPENCV12's
  // k4..k6, s1..s4 under (calib/system.h). mrcal 2.2 applies no centre-pixel
  // term (its rows are 0): the prior is on the distortions alone.
  Eigen::MatrixXd Covariance(const StateGradient& dy_db, bool regularisation_as_prior = false) const;
  // Covariance (Nparams, Nparams) of intrinsics camera `icam_intrinsics`'s
  // parameters, in mrcal's order and units; rows and columns of parameters
  // the solve did not optimise are 0.
  Eigen::MatrixXd IntrinsicsCovariance(int icam_intrinsics, bool regularisation_as_prior = false) const;
  // The joint covariance (K Nparams, K Nparams) of K intrinsics cameras'
  // parameters, camera by camera, as IntrinsicsCovariance (its K = 1): a
  // stereo pair's two lenses, solved jointly, are not independent.
  Eigen::MatrixXd JointIntrinsicsCovariance(const std::vector<int>& icams_intrinsics,
                                            bool regularisation_as_prior = false) const;
  // Covariance (6, 6) of extrinsics camera `icam_extrinsics`'s rt_cam_ref
  // (r: rotation vector, rad; t: mm).
  Eigen::Matrix<double, 6, 6> ExtrinsicsCovariance(int icam_extrinsics) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stereorig
