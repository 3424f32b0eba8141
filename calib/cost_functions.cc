#include "calib/cost_functions.h"

#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <utility>

#include "calib/core/input_error.h"
#include "calib/core/mrcal_c.h"

namespace stereorig {

PoseBlock::PoseBlock(const Pose& a_from_b) : R0(a_from_b.rotation()) {
  for (int i = 0; i < 3; ++i) params[3 + i] = a_from_b.translation_mm()(i);
}

Pose PoseBlock::ToPose() const {
  const Pose dr = Pose::FromRotationVector(Eigen::Vector3d(params[0], params[1], params[2]), Eigen::Vector3d::Zero());
  return Pose(dr.rotation() * R0, Eigen::Vector3d(params[3], params[4], params[5]));
}

namespace {

// out = (Exp(dr) R0) p + t
template <typename T>
void Apply(const Eigen::Matrix3d& R0, const T* block, const T* p, T* out) {
  T p0[3];
  for (int i = 0; i < 3; ++i) p0[i] = T(R0(i, 0)) * p[0] + T(R0(i, 1)) * p[1] + T(R0(i, 2)) * p[2];
  ceres::AngleAxisRotatePoint(block, p0, out);
  for (int i = 0; i < 3; ++i) out[i] += block[3 + i];
}

// out = (Exp(dr) R0)^-1 (p - t) = R0' Exp(-dr) (p - t)
template <typename T>
void ApplyInverse(const Eigen::Matrix3d& R0, const T* block, const T* p, T* out) {
  const T minus_dr[3] = {-block[0], -block[1], -block[2]};
  const T d[3] = {p[0] - block[3], p[1] - block[4], p[2] - block[5]};
  T r[3];
  ceres::AngleAxisRotatePoint(minus_dr, d, r);
  for (int i = 0; i < 3; ++i) out[i] = T(R0(0, i)) * r[0] + T(R0(1, i)) * r[1] + T(R0(2, i)) * r[2];
}

}  // namespace

template <typename T>
bool CornerPointFunctor::operator()(const T* board, const T* module, const T* bff, const T* rl, T* p_cam) const {
  T x[3] = {T(x_face(0)), T(x_face(1)), T(x_face(2))};
  T front[3];
  if (back_face) {
    ApplyInverse(R0[2], bff, x, front);  // front_from_back * x
  } else {
    for (int i = 0; i < 3; ++i) front[i] = x[i];
  }
  T ref[3], mod[3];
  Apply(R0[0], board, front, ref);
  ApplyInverse(R0[1], module, ref, mod);  // module_from_ref * p_ref
  if (right_camera) {
    Apply(R0[3], rl, mod, p_cam);
  } else {
    for (int i = 0; i < 3; ++i) p_cam[i] = mod[i];
  }
  return true;
}

CornerReprojectionCost::CornerReprojectionCost(const CornerPointFunctor& geometry, const Camera& camera,
                                               const Eigen::Vector2d& q_observed)
    : point_(new ceres::AutoDiffCostFunction<CornerPointFunctor, 3, 6, 6, 6, 6>(new CornerPointFunctor(geometry))),
      camera_(camera),
      q_observed_(q_observed),
      num_intrinsics_(static_cast<int>(camera.intrinsics().size())) {
  set_num_residuals(2);
  for (int i = 0; i < 4; ++i) mutable_parameter_block_sizes()->push_back(6);
  mutable_parameter_block_sizes()->push_back(num_intrinsics_);
}

bool CornerReprojectionCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  double p[3];
  double jp[4][18];
  double* jp_ptrs[4] = {jp[0], jp[1], jp[2], jp[3]};
  const bool need_pose_j = jacobians && (jacobians[0] || jacobians[1] || jacobians[2] || jacobians[3]);
  if (!point_->Evaluate(parameters, p, need_pose_j ? jp_ptrs : nullptr)) return false;
  if (!(p[2] > 0)) return false;  // behind the camera: let the solver step back

  const mrcal_point3_t pc = {.xyz = {p[0], p[1], p[2]}};
  mrcal_point2_t q;
  mrcal_point3_t dq_dp[2];
  std::vector<double> dq_dintr;
  const bool need_intr_j = jacobians && jacobians[4];
  if (need_intr_j) dq_dintr.resize(2 * num_intrinsics_);
  if (!mrcal_project(&q, dq_dp, need_intr_j ? dq_dintr.data() : nullptr, &pc, 1,
                     static_cast<const mrcal_lensmodel_t*>(camera_.mrcal_lensmodel()), parameters[4])) {
    return false;
  }
  residuals[0] = q.x - q_observed_.x();
  residuals[1] = q.y - q_observed_.y();
  if (!jacobians) return true;
  for (int b = 0; b < 4; ++b) {
    if (!jacobians[b]) continue;
    // (2,6) row-major = dq_dp (2,3) * dp_dblock (3,6) row-major
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 6; ++c) {
        jacobians[b][r * 6 + c] =
            dq_dp[r].x * jp[b][0 * 6 + c] + dq_dp[r].y * jp[b][1 * 6 + c] + dq_dp[r].z * jp[b][2 * 6 + c];
      }
  }
  if (need_intr_j) std::copy(dq_dintr.begin(), dq_dintr.end(), jacobians[4]);
  return true;
}

ceres::CostFunction* HeldIntrinsicsPrior::Create(const std::vector<double>& theta0, const std::vector<int>& held,
                                                 const std::vector<double>& covariance, double corner_sigma_px) {
  const int n = static_cast<int>(theta0.size()), h = static_cast<int>(held.size());
  if (h == 0 || covariance.size() != static_cast<size_t>(n) * n) return nullptr;
  Eigen::MatrixXd cov_held(h, h);
  for (int i = 0; i < h; ++i)
    for (int j = 0; j < h; ++j) cov_held(i, j) = covariance[static_cast<size_t>(held[i]) * n + held[j]];
  return CreateJoint({theta0}, held, cov_held, corner_sigma_px);
}

ceres::CostFunction* HeldIntrinsicsPrior::CreateJoint(const std::vector<std::vector<double>>& theta0,
                                                      const std::vector<int>& held,
                                                      const Eigen::MatrixXd& covariance_held, double corner_sigma_px) {
  const int blocks = static_cast<int>(theta0.size()), h = static_cast<int>(held.size());
  if (blocks == 0 || h == 0 || covariance_held.rows() != blocks * h || covariance_held.cols() != blocks * h)
    return nullptr;
  const int n = static_cast<int>(theta0[0].size());
  Eigen::VectorXd theta0_held(blocks * h);
  for (int b = 0; b < blocks; ++b) {
    if (static_cast<int>(theta0[b].size()) != n) return nullptr;
    for (int i = 0; i < h; ++i) theta0_held(b * h + i) = theta0[b][held[i]];
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance_held);
  if (llt.info() != Eigen::Success || !covariance_held.allFinite()) return nullptr;
  const Eigen::MatrixXd l_inverse = llt.matrixL().solve(Eigen::MatrixXd::Identity(blocks * h, blocks * h));
  if (!l_inverse.allFinite()) return nullptr;
  return new HeldIntrinsicsPrior(blocks, n, held, theta0_held, corner_sigma_px * l_inverse);
}

HeldIntrinsicsPrior::HeldIntrinsicsPrior(int num_blocks, int num_intrinsics, std::vector<int> held,
                                         Eigen::VectorXd theta0_held, Eigen::MatrixXd whiten)
    : held_(std::move(held)), theta0_held_(std::move(theta0_held)), whiten_(std::move(whiten)) {
  set_num_residuals(static_cast<int>(theta0_held_.size()));
  for (int b = 0; b < num_blocks; ++b) mutable_parameter_block_sizes()->push_back(num_intrinsics);
}

bool HeldIntrinsicsPrior::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const int h = static_cast<int>(held_.size());
  const int blocks = static_cast<int>(parameter_block_sizes().size());
  const int rows = blocks * h;
  Eigen::VectorXd d(rows);
  for (int b = 0; b < blocks; ++b)
    for (int i = 0; i < h; ++i) d(b * h + i) = parameters[b][held_[i]] - theta0_held_(b * h + i);
  Eigen::Map<Eigen::VectorXd>(residuals, rows) = whiten_ * d;
  if (!jacobians) return true;
  // Block b's (B H, N) row-major: whiten_'s columns of block b in the held
  // columns, 0 elsewhere (linear).
  for (int b = 0; b < blocks; ++b) {
    if (!jacobians[b]) continue;
    const int n = parameter_block_sizes()[b];
    std::fill(jacobians[b], jacobians[b] + rows * n, 0.0);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < h; ++c) jacobians[b][r * n + held_[c]] = whiten_(r, b * h + c);
  }
  return true;
}

}  // namespace stereorig
