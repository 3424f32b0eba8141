#include "calib/core/pose.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

TEST(Pose, ComposeAndInverseAreConsistent) {
  const Pose a_from_b = Pose::FromRotationVector({0.1, -0.2, 0.3}, {10, 20, -30});
  const Pose b_from_c = Pose::FromRotationVector({-0.4, 0.05, 0.2}, {-5, 1, 2});
  const Eigen::Vector3d p_c(1, 2, 3);
  // Composition right to left equals applying one after the other.
  EXPECT_LT(((a_from_b * b_from_c) * p_c - a_from_b * (b_from_c * p_c)).norm(), 1e-12);
  // Inverse undoes.
  EXPECT_LT((a_from_b.Inverse() * (a_from_b * p_c) - p_c).norm(), 1e-12);
  EXPECT_LT((a_from_b * a_from_b.Inverse()).AngleDeg(), 1e-12);
}

TEST(Pose, AngleAndRotationVectorMatchTheAxisAngleDefinition) {
  const double angle = 0.05 * M_PI / 180.0;  // small angles must not lose precision
  const Pose p = Pose::FromRotationVector(Eigen::Vector3d(0, angle, 0), Eigen::Vector3d::Zero());
  EXPECT_NEAR(p.AngleDeg(), 0.05, 1e-12);
  EXPECT_NEAR(p.RotationVector().y(), angle, 1e-15);
  const Pose half_turn(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix(), Eigen::Vector3d::Zero());
  EXPECT_NEAR(half_turn.AngleDeg(), 180.0, 1e-9);
}

TEST(Pose, IsRigidRejectsEachKindOfBadMatrix) {
  std::string why;
  Eigen::Matrix4d m = Pose::FromRotationVector({0.1, 0.2, 0.3}, {1, 2, 3}).ToMatrix4();
  EXPECT_TRUE(IsRigid(m, 1e-9, &why));
  Eigen::Matrix4d scaled = m;
  scaled.topLeftCorner<3, 3>() *= 1.001;
  EXPECT_FALSE(IsRigid(scaled, 1e-9, &why));
  EXPECT_NE(why.find("orthonormal"), std::string::npos);
  Eigen::Matrix4d mirrored = m;
  mirrored.col(0) *= -1;
  EXPECT_FALSE(IsRigid(mirrored, 1e-9, &why));
  EXPECT_NE(why.find("reflection"), std::string::npos);
  Eigen::Matrix4d bottom = m;
  bottom(3, 0) = 0.5;
  EXPECT_FALSE(IsRigid(bottom, 1e-9, &why));
  Eigen::Matrix4d nan = m;
  nan(0, 3) = std::nan("");
  EXPECT_FALSE(IsRigid(nan, 1e-9, &why));
}

}  // namespace
}  // namespace stereorig
