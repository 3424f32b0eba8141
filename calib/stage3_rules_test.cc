// Stage 3's rules taken alone (calib/system.h, calib/convergence.h): which
// intrinsics it holds per lens model, that its covariance refuses a problem
// with an undetermined direction, and that a solve that stopped short is
// named as not converged. The whole calibration with OPENCV12:
// CalibrateSystemVerdicts.OpenCv12RefinesItsRationalAndPrismTermsUnderAPriorAndConverges.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "calib/convergence.h"
#include "calib/system.h"

namespace stereorig {
namespace {

std::vector<int> Range(int from, int to) {
  std::vector<int> v;
  for (int i = from; i < to; ++i) v.push_back(i);
  return v;
}

// mrcal's order: fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4.
TEST(Stage3Rules, HeldIntrinsicsPerLensModel) {
  EXPECT_EQ(Stage3HeldIntrinsics("LENSMODEL_OPENCV4", 8), std::vector<int>{});
  EXPECT_EQ(Stage3HeldIntrinsics("LENSMODEL_OPENCV5", 9), std::vector<int>{});
  EXPECT_EQ(Stage3HeldIntrinsics("LENSMODEL_OPENCV8", 12), Range(9, 12));   // k4..k6
  EXPECT_EQ(Stage3HeldIntrinsics("LENSMODEL_OPENCV12", 16), Range(9, 16));  // k4..k6, s1..s4
  const std::string spline = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=45";
  EXPECT_EQ(Stage3HeldIntrinsics(spline, 4 + 2 * 8 * 6), Range(4, 4 + 2 * 8 * 6));  // every knot
}

// r = x + y - 1: only x + y is determined, x - y is not.
struct SumResidual {
  template <typename T>
  bool operator()(const T* x, const T* y, T* r) const {
    r[0] = x[0] + y[0] - 1.0;
    return true;
  }
};
ceres::CostFunction* Sum() { return new ceres::AutoDiffCostFunction<SumResidual, 1, 1, 1>(new SumResidual); }

// A problem with an undetermined direction gets no covariance: with
// null_space_rank = -1 Ceres returned the pseudo-inverse (Var(x) = 0.125
// here, where x is not determined at all) and stage 3 reported it as "ok".
// Two observations of x + y: the Jacobian [[1, 1], [1, 1]] is tall, as
// stage 3's is (a wide one hides its null direction from Ceres's SVD).
// Computed as stage 3 does, without Ceres's glog line on the failure.
TEST(Stage3Rules, CovarianceOfAnUndeterminedProblemFails) {
  double x = 0.3, y = 0.7, z = 0.0;
  ceres::Problem problem;
  problem.AddResidualBlock(Sum(), nullptr, &x, &y);
  problem.AddResidualBlock(Sum(), nullptr, &x, &y);
  const std::vector<std::pair<const double*, const double*>> xx = {{&x, &x}};
  ceres::Covariance undetermined(Stage3CovarianceOptions(2));
  EXPECT_FALSE(ComputeCovarianceQuietly(&undetermined, xx, &problem));
  // y observed alone too (r = y + z - 1, z held): J = [[1, 1], [1, 1], [0, 1]],
  // J'J = [[2, 2], [2, 3]], whose inverse's (0, 0) is 3 / 2.
  problem.AddResidualBlock(Sum(), nullptr, &y, &z);
  problem.SetParameterBlockConstant(&z);
  ceres::Covariance determined(Stage3CovarianceOptions(2));
  ASSERT_TRUE(ComputeCovarianceQuietly(&determined, xx, &problem));
  double var_x = 0;
  determined.GetCovarianceBlock(&x, &x, &var_x);
  EXPECT_NEAR(var_x, 1.5, 1e-9);
}

// r = a x: one parameter observed with slope a.
struct ScaledResidual {
  double a;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    r[0] = T(a) * x[0];
    return true;
  }
};
ceres::CostFunction* Scaled(double a) {
  return new ceres::AutoDiffCostFunction<ScaledResidual, 1, 1>(new ScaledResidual{a});
}

// A direction merely weak beside the others is given its (wide) sigma: a
// rotation's column (rad) is ~1e4 x a principal point's (px) in stage 3's
// Jacobian, and OPENCV12's principal points under their prior, a few px
// uncertain, put its smallest singular value at 6e-8 of the largest on the
// demo dataset; under Ceres's default (1e-7) stage 3 gave no sigma at all.
// Here x is seen with slope 1e4, y with 1e-4 (twice each, J tall): singular
// values 1e-8 apart, well above double's rounding.
TEST(Stage3Rules, CovarianceOfAWeakButDeterminedDirectionIsGiven) {
  double x = 0.0, y = 0.0;
  ceres::Problem problem;
  for (int i = 0; i < 2; ++i) {
    problem.AddResidualBlock(Scaled(1e4), nullptr, &x);
    problem.AddResidualBlock(Scaled(1e-4), nullptr, &y);
  }
  const std::vector<std::pair<const double*, const double*>> yy = {{&y, &y}};
  ceres::Covariance covariance(Stage3CovarianceOptions(2));
  ASSERT_TRUE(ComputeCovarianceQuietly(&covariance, yy, &problem));
  double var_y = 0;
  covariance.GetCovarianceBlock(&y, &y, &var_y);
  EXPECT_NEAR(var_y, 1.0 / (2 * 1e-8), 1e-6 / (2 * 1e-8));  // inv(J'J) = 1 / (2 a^2)
}

// A report whose stage 3 solve stopped short is refused whatever its RMS,
// naming stage 3 and why; a converged one with the same figures passes.
TEST(Stage3Rules, ASolveThatStoppedShortIsNotConverged) {
  CalibrationReport r;
  r.num_modules = 2;
  for (int k = 0; k < 4; ++k) {
    IntrinsicsReport c;
    c.camera = k;
    c.rms_px = 0.2;
    r.intrinsics.push_back(c);
  }
  for (int m = 0; m < 2; ++m) {
    StereoReport s;
    s.module = m;
    s.rms_px = 0.2;
    r.stereo.push_back(s);
  }
  r.system.refined_reprojection_rms_px = 0.2;
  r.system.refined_median_corner_residual_px = 0.24;
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.system.solver_problem = "Ceres ended at NO_CONVERGENCE after 100 iterations (Maximum number of iterations reached)";
  const std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_EQ(p.rfind("stage 3 did not converge: Ceres ended at NO_CONVERGENCE after 100 iterations", 0), 0u) << p;
  EXPECT_NE(p.find("at rms 0.2 px"), std::string::npos) << p;
  // Residuals that could not be evaluated read NaN: named as such, not as
  // an RMS of nan.
  r.system.solver_problem = "its residuals could not be evaluated (a projection failed)";
  r.system.refined_reprojection_rms_px = std::numeric_limits<double>::quiet_NaN();
  r.system.refined_median_corner_residual_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(NotConvergedProblem(r, 1.0).rfind("stage 3 did not converge: its residuals could not be evaluated", 0), 0u)
      << NotConvergedProblem(r, 1.0);
  EXPECT_EQ(NotConvergedProblem(r, 1.0).find("nan"), std::string::npos) << NotConvergedProblem(r, 1.0);
  r.num_modules = 1;  // no stage 3
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
}

}  // namespace
}  // namespace stereorig
