// Horn's absolute orientation against an analytic case and against an
// independent method (Eigen's Umeyama, SVD-based).
#include "calib/horn.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace stereorig {
namespace {

TEST(Horn, AnalyticQuarterTurn) {
  // b: the unit cube's corners. a = Rz(90 deg) b + (10, -5, 2): x -> y, y -> -x.
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    b.push_back(p);
    a.push_back(Eigen::Vector3d(-p.y(), p.x(), p.z()) + Eigen::Vector3d(10, -5, 2));
  }
  const HornResult h = HornAbsoluteOrientation(a, b);
  ASSERT_TRUE(h.ok);
  Eigen::Matrix3d R;
  R << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_LT((h.a_from_b.rotation() - R).norm(), 1e-12);
  EXPECT_LT((h.a_from_b.translation_mm() - Eigen::Vector3d(10, -5, 2)).norm(), 1e-12);
  EXPECT_LT(h.rms_mm, 1e-12);
}

TEST(Horn, HalfTurnIsFound) {
  // A rotation by pi (two facing modules): the quaternion's w is 0.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-100, 100);
  const Pose truth(Eigen::AngleAxisd(M_PI, Eigen::Vector3d(0.1, 1, 0).normalized()).toRotationMatrix(),
                   Eigen::Vector3d(3, 1, 400));
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < 20; ++i) {
    b.emplace_back(u(rng), u(rng), u(rng));
    a.push_back(truth * b.back());
  }
  const HornResult h = HornAbsoluteOrientation(a, b);
  ASSERT_TRUE(h.ok);
  EXPECT_LT((truth.Inverse() * h.a_from_b).AngleDeg(), 1e-9);
  EXPECT_LT((h.a_from_b.translation_mm() - truth.translation_mm()).norm(), 1e-9);
}

TEST(Horn, AgreesWithUmeyamaOnNoisyPoints) {
  for (unsigned seed = 0; seed < 20; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::normal_distribution<double> noise(0, 0.05);  // mm
    const Pose truth = Pose::FromRotationVector(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2.0,
                                                Eigen::Vector3d(u(rng), u(rng), u(rng)) * 300.0);
    std::vector<Eigen::Vector3d> a, b;
    Eigen::Matrix3Xd A(3, 40), B(3, 40);
    for (int i = 0; i < 40; ++i) {
      b.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 80.0);
      a.push_back(truth * b.back() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
      A.col(i) = a.back();
      B.col(i) = b.back();
    }
    const HornResult h = HornAbsoluteOrientation(a, b);
    ASSERT_TRUE(h.ok);
    const Eigen::Matrix4d T = Eigen::umeyama(B, A, false);
    // Both minimise the same least-squares cost, whose minimiser is unique:
    // they must agree to rounding, far below the injected noise.
    EXPECT_LT((h.a_from_b.rotation() - T.topLeftCorner<3, 3>()).norm(), 1e-10) << seed;
    EXPECT_LT((h.a_from_b.translation_mm() - T.topRightCorner<3, 1>()).norm(), 1e-8) << seed;
    // And the fit residual is the injected noise: sqrt(3) * 0.05 mm, less the
    // 6 fitted degrees of freedom, within sampling error.
    EXPECT_NEAR(h.rms_mm, 0.05 * std::sqrt(3.0 * (40 - 2) / 40.0), 0.02) << seed;
  }
}

TEST(Horn, WeightsSelectPoints) {
  // Zero weights on gross outliers give the inliers' fit exactly.
  const Pose truth = Pose::FromRotationVector(Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(1, 2, 3));
  std::vector<Eigen::Vector3d> a, b;
  std::vector<double> w;
  for (int i = 0; i < 10; ++i) {
    b.emplace_back(i, i * i % 7, i % 3);
    a.push_back(truth * b.back() + (i < 2 ? Eigen::Vector3d(50, 0, 0) : Eigen::Vector3d::Zero()));
    w.push_back(i < 2 ? 0.0 : 1.0);
  }
  const HornResult h = HornAbsoluteOrientation(a, b, w);
  ASSERT_TRUE(h.ok);
  EXPECT_LT((truth.Inverse() * h.a_from_b).AngleDeg(), 1e-9);
  EXPECT_LT((truth.translation_mm() - h.a_from_b.translation_mm()).norm(), 1e-9);
}

TEST(Horn, RefusesCollinearAndTooFewPoints) {
  std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  EXPECT_FALSE(HornAbsoluteOrientation(line, line).ok);
  std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_FALSE(HornAbsoluteOrientation(two, two).ok);
}

}  // namespace
}  // namespace stereorig
