#include "calib/core/rig.h"

#include <gtest/gtest.h>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

// A rig of M modules, each with two pinhole cameras, at arbitrary poses.
Rig MakeRig(int m) {
  std::vector<Camera> cams;
  std::vector<std::string> names;
  std::vector<StereoModule> mods;
  std::vector<Pose> module0_from_module;
  for (int i = 0; i < m; ++i) {
    for (int k = 0; k < 2; ++k) {
      cams.emplace_back("LENSMODEL_PINHOLE", std::vector<double>{1000, 1000, 320, 240}, 640, 480);
      names.push_back("cam" + std::to_string(2 * i + k));
    }
    mods.push_back(
        {"module" + std::to_string(i), 2 * i, 2 * i + 1, Pose::FromRotationVector({0, -0.1, 0}, {-90, 0, 5})});
    module0_from_module.push_back(i == 0 ? Pose::Identity()
                                         : Pose::FromRotationVector({0.1 * i, 2.0 * i, -0.2}, {30.0 * i, -5, 400}));
  }
  return Rig(cams, names, mods, module0_from_module);
}

TEST(Rig, BuildsAConsistentSForAnyModuleCount) {
  for (int m : {1, 2, 3, 5}) {
    const Rig rig = MakeRig(m);
    std::string why;
    EXPECT_TRUE(rig.CheckS(&why)) << why;
    ASSERT_EQ(rig.num_modules(), m);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        const Eigen::Vector3d p(1, 2, 3);
        // S_ij maps j's coordinates into i's: going through module 0 agrees.
        EXPECT_LT((rig.S(i, j) * p - rig.S(i, 0) * (rig.S(0, j) * p)).norm(), 1e-9);
      }
  }
}

TEST(Rig, RejectsAnInconsistentS) {
  const Rig good = MakeRig(3);
  auto S = good.S();
  // Perturb one entry by far more than the tolerance (1 um): S_01 S_12 != S_02.
  S[0][2] = Pose(S[0][2].rotation(), S[0][2].translation_mm() + Eigen::Vector3d(1e-3, 0, 0));
  S[2][0] = S[0][2].Inverse();
  EXPECT_THROW(Rig(good.cameras(), good.camera_names(), good.modules(), S, "test"), InputError);
  auto S2 = good.S();
  S2[1][0] = Pose::FromRotationVector({0, 0, 1e-6}, {0, 0, 0}) * S2[1][0];  // not the inverse of S_01
  EXPECT_THROW(Rig(good.cameras(), good.camera_names(), good.modules(), S2, "test"), InputError);
  auto S3 = good.S();
  S3[1][1] = Pose::FromRotationVector({0, 0, 0}, {0, 0, 1e-3});
  EXPECT_THROW(Rig(good.cameras(), good.camera_names(), good.modules(), S3, "test"), InputError);
  // Within tolerance (a 1e-9 mm perturbation): accepted.
  auto S4 = good.S();
  S4[0][1] = Pose(S4[0][1].rotation(), S4[0][1].translation_mm() + Eigen::Vector3d(1e-9, 0, 0));
  EXPECT_NO_THROW(Rig(good.cameras(), good.camera_names(), good.modules(), S4, "test"));
}

TEST(Rig, RejectsModulesThatNameMissingCameras) {
  const Rig good = MakeRig(2);
  auto mods = good.modules();
  mods[1].right_camera = 7;
  EXPECT_THROW(Rig(good.cameras(), good.camera_names(), mods, good.S(), "test"), InputError);
}

// A module left out of a hand-edited rig file leaves its cameras in none:
// the refusal names them.
TEST(Rig, NamesTheCamerasNoModuleHolds) {
  const Rig good = MakeRig(2);
  auto mods = good.modules();
  mods.pop_back();
  try {
    Rig(good.cameras(), good.camera_names(), mods, std::vector<std::vector<Pose>>{{Pose::Identity()}}, "rig.yaml");
    ADD_FAILURE() << "cameras in no module accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "rig.yaml: every camera must belong to exactly one module: camera(s) 2, 3 in none");
  }
}

TEST(Rig, CamFromReferenceChainsModuleAndStereoPoses) {
  const Rig rig = MakeRig(2);
  const Pose expected = rig.module(1).right_from_left * rig.S(1, 0);
  EXPECT_LT((rig.CamFromReference(3) * Pose(expected.Inverse())).AngleDeg(), 1e-12);
  EXPECT_LT((rig.CamFromReference(3) * Pose(expected.Inverse())).DistanceMm(), 1e-12);
}

}  // namespace
}  // namespace stereorig
