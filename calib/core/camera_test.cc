#include "calib/core/camera.h"

#include <gtest/gtest.h>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

Camera Opencv8() {
  return Camera("LENSMODEL_OPENCV8", {1024, 1025, 375.5, 290.5, -0.1, 0.09, 2e-4, -1e-4, -0.02, 0, 0, 0}, 752, 582);
}

TEST(Camera, PinholePartMatchesTheTextbookFormula) {
  const Camera pinhole("LENSMODEL_PINHOLE", {1000, 1010, 300, 200}, 640, 480);
  const Eigen::Vector2d q = pinhole.Project({10, -20, 200});
  EXPECT_NEAR(q.x(), 1000 * 10 / 200.0 + 300, 1e-12);
  EXPECT_NEAR(q.y(), 1010 * -20 / 200.0 + 200, 1e-12);
}

TEST(Camera, UnprojectInvertsProject) {
  const Camera cam = Opencv8();
  for (double x : {0.0, 100.0, 375.5, 700.0}) {
    for (double y : {0.0, 290.5, 581.0}) {
      Eigen::Vector3d v;
      ASSERT_TRUE(cam.Unproject({x, y}, &v));
      EXPECT_NEAR(v.norm(), 1.0, 1e-12);
      const Eigen::Vector2d q = cam.Project(v * 200.0);
      EXPECT_NEAR(q.x(), x, 1e-6);
      EXPECT_NEAR(q.y(), y, 1e-6);
    }
  }
}

TEST(Camera, ProjectionGradientMatchesFiniteDifferences) {
  const Camera cam = Opencv8();
  const Eigen::Vector3d p(30, -20, 210);
  Eigen::Matrix<double, 2, 3> dq_dp;
  cam.Project(p, &dq_dp);
  const double h = 1e-5;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d dp = Eigen::Vector3d::Zero();
    dp[c] = h;
    const Eigen::Vector2d num = (cam.Project(p + dp) - cam.Project(p - dp)) / (2 * h);
    EXPECT_NEAR(num.x(), dq_dp(0, c), 1e-6);
    EXPECT_NEAR(num.y(), dq_dp(1, c), 1e-6);
  }
}

TEST(Camera, RejectsUnknownModelsAndWrongIntrinsicCounts) {
  EXPECT_THROW(Camera("LENSMODEL_NOPE", {1, 1, 1, 1}, 10, 10), InputError);
  EXPECT_THROW(Camera("LENSMODEL_OPENCV8", {1000, 1000, 300, 200}, 640, 480), InputError);
  EXPECT_THROW(Camera("LENSMODEL_PINHOLE", {1000, std::nan(""), 300, 200}, 640, 480), InputError);
  EXPECT_THROW(Camera("LENSMODEL_PINHOLE", {1000, 1000, 300, 200}, 0, 480), InputError);
  // A splined model needs its configuration.
  EXPECT_EQ(Camera::NumIntrinsics("LENSMODEL_SPLINED_STEREOGRAPHIC"), -1);
  EXPECT_EQ(Camera::NumIntrinsics("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=10_Ny=8_fov_x_deg=60"), 4 + 2 * 10 * 8);
  EXPECT_EQ(Camera::NumIntrinsics("LENSMODEL_OPENCV8"), 12);
}

}  // namespace
}  // namespace stereorig
