// The stage-3 reprojection cost: its hand-chained Jacobian (autodiff pose
// chain x mrcal's analytic projection gradients) against central numeric
// differences, for every parameter block, for a left and a right camera, the
// front and the back face, and two lens models. The held intrinsics' prior.
#include "calib/cost_functions.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

namespace stereorig {
namespace {

void CheckJacobians(const Camera& camera, bool back, bool right, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  PoseBlock board(Pose::FromRotationVector(Eigen::Vector3d(0.2 * u(rng), 0.2 * u(rng), 0.1 * u(rng)),
                                           Eigen::Vector3d(-40 + 5 * u(rng), -30, 200)));
  PoseBlock module(Pose::FromRotationVector(Eigen::Vector3d(0.02 * u(rng), 0.03, 0.01), Eigen::Vector3d(1, 2, 3)));
  PoseBlock bff(Pose(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix(), Eigen::Vector3d(96, 0, 3)));
  PoseBlock rl(Pose::FromRotationVector(Eigen::Vector3d(0, -0.1, 0), Eigen::Vector3d(-90, 0, 5)));
  // Non-zero perturbation parts, so the derivatives are taken away from 0.
  for (PoseBlock* b : {&board, &module, &bff, &rl})
    for (int i = 0; i < 3; ++i) b->params[i] = 0.01 * u(rng);
  CornerPointFunctor g;
  g.x_face = Eigen::Vector3d(36, 24, 0);
  g.back_face = back;
  g.right_camera = right;
  g.R0[0] = board.R0;
  g.R0[1] = module.R0;
  g.R0[2] = bff.R0;
  g.R0[3] = rl.R0;
  std::unique_ptr<ceres::CostFunction> cost(CornerReprojectionCost::Create(g, camera, Eigen::Vector2d(300, 200)));
  std::vector<double> intr = camera.intrinsics();
  std::vector<double*> params = {board.params, module.params, bff.params, rl.params, intr.data()};
  const std::vector<int> sizes = {6, 6, 6, 6, static_cast<int>(intr.size())};
  std::vector<std::vector<double>> J(5);
  std::vector<double*> Jp(5);
  for (int b = 0; b < 5; ++b) {
    J[b].resize(2 * sizes[b]);
    Jp[b] = J[b].data();
  }
  double r[6];  // 2 used (see below)
  ASSERT_TRUE(cost->Evaluate(params.data(), r, Jp.data()));
  for (int b = 0; b < 5; ++b) {
    for (int i = 0; i < sizes[b]; ++i) {
      const double h = b == 4 ? 1e-6 * std::max(1.0, std::abs(params[b][i])) : 1e-6;
      const double saved = params[b][i];
      double rp[6], rm[6];  // 2 used; sized so GCC's devirtualising bounds check stays quiet
      params[b][i] = saved + h;
      ASSERT_TRUE(cost->Evaluate(params.data(), rp, nullptr));
      params[b][i] = saved - h;
      ASSERT_TRUE(cost->Evaluate(params.data(), rm, nullptr));
      params[b][i] = saved;
      for (int k = 0; k < 2; ++k) {
        const double numeric = (rp[k] - rm[k]) / (2 * h);
        // Central differences: truncation ~h^2 |q'''|, rounding ~1e-16 |q| / h.
        EXPECT_NEAR(J[b][k * sizes[b] + i], numeric, 1e-5 * std::max(1.0, std::abs(numeric)))
            << "block " << b << " param " << i << " residual " << k << " back " << back << " right " << right;
      }
    }
  }
}

TEST(CornerReprojectionCost, JacobiansMatchNumericOpencv8) {
  const Camera cam("LENSMODEL_OPENCV8", {1020, 1022, 375, 290, -0.11, 0.09, 2e-4, -1e-4, -0.02, 0.001, 0, 0}, 752, 582);
  for (bool back : {false, true})
    for (bool right : {false, true}) CheckJacobians(cam, back, right, 1 + back + 2 * right);
}

TEST(CornerReprojectionCost, JacobiansMatchNumericSplined) {
  const std::string model = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=60";
  std::vector<double> intr = {1020, 1021, 375, 290};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 2 * 8 * 6; ++i) intr.push_back(0.01 * u(rng));
  const Camera cam(model, intr, 752, 582);
  CheckJacobians(cam, true, true, 7);
}

// The held intrinsics' prior: residual corner_sigma_px * L^-1 (theta_h -
// theta_h0) with L L' the held block of the covariance, so that its squared
// norm is corner_sigma_px^2 times the Mahalanobis distance d' C^-1 d, and
// its Jacobian that linear map in the held columns, 0 in the others.
TEST(HeldIntrinsicsPrior, WhitensByTheHeldBlockOfTheCovariance) {
  const std::vector<double> theta0 = {1000, 1000, 376, 291, 0.1, 0.2};
  const std::vector<int> held = {4, 5};
  std::vector<double> covariance(36, 0.0);
  for (int i = 0; i < 6; ++i) covariance[i * 6 + i] = 1.0;
  covariance[4 * 6 + 4] = 4e-4, covariance[5 * 6 + 5] = 1e-4, covariance[4 * 6 + 5] = covariance[5 * 6 + 4] = 1e-4;
  std::unique_ptr<ceres::CostFunction> prior(HeldIntrinsicsPrior::Create(theta0, held, covariance, 0.2));
  ASSERT_NE(prior, nullptr);
  ASSERT_EQ(prior->num_residuals(), 2);
  const std::vector<double> theta = {990, 1003, 370, 300, 0.13, 0.19};  // the core's moves cost nothing
  const double* params[] = {theta.data()};
  double r[2], j[2 * 6];
  double* jacobians[] = {j};
  ASSERT_TRUE(prior->Evaluate(params, r, jacobians));
  Eigen::Matrix2d c;
  c << 4e-4, 1e-4, 1e-4, 1e-4;
  const Eigen::Vector2d d(0.03, -0.01);
  EXPECT_NEAR(r[0] * r[0] + r[1] * r[1], 0.04 * d.dot(c.inverse() * d), 1e-9);
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 4; ++col) EXPECT_EQ(j[row * 6 + col], 0.0);
    // Linear: r = J d over the held columns.
    EXPECT_NEAR(j[row * 6 + 4] * d(0) + j[row * 6 + 5] * d(1), r[row], 1e-12);
  }
  // No covariance, or a held block that is not positive definite: no prior.
  EXPECT_EQ(HeldIntrinsicsPrior::Create(theta0, held, {}, 0.2), nullptr);
  covariance[5 * 6 + 5] = 0.0;
  EXPECT_EQ(HeldIntrinsicsPrior::Create(theta0, held, covariance, 0.2), nullptr);
}

// The prior over a stereo pair's two cameras at once (CreateJoint): stage
// 2 solved their lenses jointly, so their held terms are correlated. One
// residual block over both parameter blocks: its squared norm is
// corner_sigma_px^2 times the joint Mahalanobis distance d' C^-1 d of the
// stacked moves, which independent priors (C's off-diagonal block
// dropped) do not give; each block's Jacobian is that linear map in its
// held columns.
TEST(HeldIntrinsicsPrior, AJointPriorWhitensByTheJointCovariance) {
  const std::vector<double> left0 = {1000, 1000, 376, 291, 0.1, 0.2}, right0 = {1010, 1010, 370, 290, -0.1, 0.3};
  const std::vector<int> held = {4, 5};
  Eigen::Matrix4d c;  // left's k, right's k; a correlation of 0.6 between the pair's first terms
  c << 4e-4, 1e-4, 1.2e-4, 0, 1e-4, 1e-4, 0, 0, 1.2e-4, 0, 1e-4, 0, 0, 0, 0, 2e-4;
  std::unique_ptr<ceres::CostFunction> prior(HeldIntrinsicsPrior::CreateJoint({left0, right0}, held, c, 0.2));
  ASSERT_NE(prior, nullptr);
  ASSERT_EQ(prior->num_residuals(), 4);
  ASSERT_EQ(prior->parameter_block_sizes(), (std::vector<int32_t>{6, 6}));
  const std::vector<double> left = {990, 1003, 370, 300, 0.13, 0.19}, right = {1000, 1000, 360, 280, -0.11, 0.32};
  const double* params[] = {left.data(), right.data()};
  double r[4], jl[4 * 6], jr[4 * 6];
  double* jacobians[] = {jl, jr};
  ASSERT_TRUE(prior->Evaluate(params, r, jacobians));
  const Eigen::Vector4d d(0.03, -0.01, -0.01, 0.02);
  const double joint = 0.04 * d.dot(c.inverse() * d);
  EXPECT_NEAR(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3], joint, 1e-9);
  Eigen::Matrix4d independent = c;
  independent.block<2, 2>(0, 2).setZero();
  independent.block<2, 2>(2, 0).setZero();
  EXPECT_GT(std::abs(0.04 * d.dot(independent.inverse() * d) - joint), 0.1);  // the cross terms matter here
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      EXPECT_EQ(jl[row * 6 + col], 0.0);
      EXPECT_EQ(jr[row * 6 + col], 0.0);
    }
    EXPECT_NEAR(jl[row * 6 + 4] * d(0) + jl[row * 6 + 5] * d(1) + jr[row * 6 + 4] * d(2) + jr[row * 6 + 5] * d(3),
                r[row], 1e-12);
  }
  // A joint covariance that is not positive definite, or of the wrong size: no prior.
  Eigen::Matrix4d singular = c;
  singular(0, 2) = singular(2, 0) = 2.1e-4;  // correlation 1.05
  EXPECT_EQ(HeldIntrinsicsPrior::CreateJoint({left0, right0}, held, singular, 0.2), nullptr);
  EXPECT_EQ(HeldIntrinsicsPrior::CreateJoint({left0, right0}, held, c.topLeftCorner<2, 2>(), 0.2), nullptr);
}

}  // namespace
}  // namespace stereorig
