// Ceres cost functions of stage 3's bundle adjustment.
//
// Every pose parameter block is 6 numbers (dr: rotation vector, rad; t: mm)
// meaning a_from_b = (Exp(dr) * R0, t) around a fixed seed rotation R0 held by
// the cost function. The block stays small, away from the angle-axis
// singularity at pi (module 1 of a facing rig is turned by pi), and its
// covariance is directly a rotation perturbation in frame a (rad) and a
// translation (mm).
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "calib/core/camera.h"
#include "calib/core/pose.h"

namespace stereorig {

// A pose parameter block and its seed rotation.
struct PoseBlock {
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
  double params[6] = {0, 0, 0, 0, 0, 0};  // dr (rad), t (mm)
  PoseBlock() = default;
  explicit PoseBlock(const Pose& a_from_b);
  Pose ToPose() const;
};

// The point of one target corner in a camera's frame, as a function of
//   [0] ref_from_front   (the board pose of the capture, reference frame)
//   [1] ref_from_module  (S[0][k]; a constant identity for module 0)
//   [2] back_from_front  (used only for a back-face corner)
//   [3] right_from_left  (used only for a right camera)
// Output (3,): p_cam, mm.
struct CornerPointFunctor {
  Eigen::Vector3d x_face;  // corner in its face's frame, mm
  bool back_face = false;
  bool right_camera = false;
  Eigen::Matrix3d R0[4];  // seed rotations of the four blocks

  template <typename T>
  bool operator()(const T* board, const T* module, const T* bff, const T* rl, T* p_cam) const;
};

// Reprojection residual (2,) = project(p_cam) - q_observed, px. Parameter
// blocks: the four poses of CornerPointFunctor (6 each), then the camera's
// intrinsics (Nintrinsics). The pose chain is differentiated automatically;
// the projection's Jacobian (wrt p_cam and the intrinsics) is mrcal's,
// analytic, chained by hand here.
class CornerReprojectionCost : public ceres::CostFunction {
 public:
  CornerReprojectionCost(const CornerPointFunctor& geometry, const Camera& camera, const Eigen::Vector2d& q_observed);
  static ceres::CostFunction* Create(const CornerPointFunctor& geometry, const Camera& camera,
                                     const Eigen::Vector2d& q_observed) {
    return new CornerReprojectionCost(geometry, camera, q_observed);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  std::unique_ptr<ceres::CostFunction> point_;  // AutoDiff of CornerPointFunctor, (3; 6,6,6,6)
  Camera camera_;                               // lens model (its intrinsics come from the parameter block)
  Eigen::Vector2d q_observed_;
  int num_intrinsics_;
};

// Prior on back_from_front: residual (6,) = corner_sigma_px * [dr (deg) / sigma_r, (t - t_measured) / sigma_t],
// dr being the block's rotation perturbation around the measured rotation.
// The reprojection residuals are in px with noise corner_sigma_px; scaling the
// whitened prior by it weighs prior and data as a MAP estimate does, and keeps
// the covariance right when it is scaled by the pixel variance.
struct BackFromFrontPrior {
  Eigen::Vector3d t_measured_mm;
  // [rx, ry, rz (deg), tx, ty, tz (mm)]; 0: the axis is known exactly, held
  // at the file's value by the caller (a SubsetManifold), its residual 0.
  Eigen::Matrix<double, 6, 1> sigma;
  double corner_sigma_px;
  template <typename T>
  bool operator()(const T* bff, T* r) const {
    for (int i = 0; i < 3; ++i)
      r[i] = sigma(i) > 0 ? T(corner_sigma_px) * bff[i] * T(180.0 / M_PI) / T(sigma(i)) : T(0);
    for (int i = 0; i < 3; ++i)
      r[3 + i] = sigma(3 + i) > 0 ? T(corner_sigma_px) * (bff[3 + i] - T(t_measured_mm(i))) / T(sigma(3 + i)) : T(0);
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& t_measured_mm, const Eigen::Matrix<double, 6, 1>& sigma,
                                     double corner_sigma_px) {
    return new ceres::AutoDiffCostFunction<BackFromFrontPrior, 6, 6>(
        new BackFromFrontPrior{t_measured_mm, sigma, corner_sigma_px});
  }
};

// Prior on the intrinsics stage 3 cannot determine alone
// (Stage3HeldIntrinsics): residual (H,) = corner_sigma_px * L^-1 (theta_h -
// theta_h0), theta_h the block's parameters at indices `held`, theta_h0
// their stage-2 values, L L' stage 2's covariance of them. Whitened and
// weighed against the corner noise as BackFromFrontPrior, so that they move
// only as far as stage 2 left them uncertain (not to a pole-zero pair) and
// their uncertainty enters the covariance of S.
class HeldIntrinsicsPrior : public ceres::CostFunction {
 public:
  // `theta0`: the block's (N,) stage-2 values; `covariance`: stage 2's (N *
  // N,) row-major, of which the `held` rows and columns are taken. Null if it
  // is empty or that block is not positive definite (no prior to refine
  // under: the caller holds them).
  static ceres::CostFunction* Create(const std::vector<double>& theta0, const std::vector<int>& held,
                                     const std::vector<double>& covariance, double corner_sigma_px);
  // The same over several blocks of one lens model at once (a stereo
  // pair's two cameras, solved jointly in stage 2): `theta0[b]` block b's
  // (N,) values, `covariance_held` the joint covariance (B H, B H) of their
  // `held` parameters, block by block. Null if it is not positive definite.
  static ceres::CostFunction* CreateJoint(const std::vector<std::vector<double>>& theta0, const std::vector<int>& held,
                                          const Eigen::MatrixXd& covariance_held, double corner_sigma_px);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  HeldIntrinsicsPrior(int num_blocks, int num_intrinsics, std::vector<int> held, Eigen::VectorXd theta0_held,
                      Eigen::MatrixXd whiten);
  std::vector<int> held_;
  Eigen::VectorXd theta0_held_;  // (B H,)
  Eigen::MatrixXd whiten_;       // (B H, B H) corner_sigma_px * L^-1
};

}  // namespace stereorig
