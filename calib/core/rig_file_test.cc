#include "calib/core/rig_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

Rig MakeRandomRig(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Camera> cams;
  std::vector<std::string> names;
  for (int i = 0; i < 4; ++i) {
    // Values with full 53-bit mantissas, so a lossy writer would show.
    cams.emplace_back(
        "LENSMODEL_OPENCV8",
        std::vector<double>{1024 + u(rng), 1024 + u(rng), 375.5 + u(rng), 290.5 + u(rng), 0.1 * u(rng), 0.1 * u(rng),
                            1e-3 * u(rng), 1e-3 * u(rng), 0.01 * u(rng), 1e-4 * u(rng), 0, -1e-17 * u(rng)},
        752, 582);
    names.push_back("cam" + std::to_string(i));
  }
  const Pose rfl = Pose::FromRotationVector({0.01 * u(rng), -0.1047 + 0.01 * u(rng), 0.01 * u(rng)},
                                            {-90 + u(rng), u(rng), 5 + u(rng)});
  std::vector<StereoModule> mods = {{"module0", 0, 1, rfl}, {"module1", 2, 3, rfl}};
  Rig rig(cams, names, mods,
          {Pose::Identity(), Pose::FromRotationVector({0.01 * u(rng), M_PI - 0.01, 0.02 * u(rng)}, {90, 1, 400})});
  rig.provenance() = {"stereorig test",
                      "2026-11-23T00:00:00Z",
                      "a \"quoted\" input\\path",
                      {{"stage1_rms_px", 0.1 + u(rng)}},
                      {{"S_0_1_mm", 1e-3 * (2 + u(rng))}}};
  return rig;
}

TEST(RigFile, WriteReadWriteIsBitIdentical) {
  const std::string dir = ::testing::TempDir();
  for (unsigned seed = 0; seed < 20; ++seed) {
    const Rig rig = MakeRandomRig(seed);
    const std::string path = dir + "/rig_roundtrip.yaml";
    WriteRigFile(rig, path);
    const Rig back = ReadRigFile(path);
    EXPECT_EQ(RigToYaml(back), RigToYaml(rig));
    // Every double survives exactly, not merely "close".
    for (int c = 0; c < rig.num_cameras(); ++c) EXPECT_EQ(back.camera(c).intrinsics(), rig.camera(c).intrinsics());
    EXPECT_EQ(back.S(0, 1).ToMatrix4(), rig.S(0, 1).ToMatrix4());
    EXPECT_EQ(back.module(1).right_from_left.ToMatrix4(), rig.module(1).right_from_left.ToMatrix4());
    EXPECT_EQ(back.provenance().input, rig.provenance().input);
    EXPECT_EQ(back.provenance().residuals, rig.provenance().residuals);
  }
}

// Cameras read out in windows of a 1920 x 1200 sensor (f = 1365 px, the
// principal point at its centre): a 640 x 480 corner and a 1920 x 200
// strip at the bottom, whose principal points (window coordinates) lie off
// them. The reader's lens check admits them (calib/core/lens_plausibility.h).
TEST(RigFile, WindowedCamerasAreRead) {
  const std::vector<double> distortion = {-0.11, 0.09, 2e-4, -1e-4, -0.02, 0, 0, 0};
  std::vector<double> corner = {1365, 1365, 959.5 - 1280, 599.5 - 720}, strip = {1365, 1365, 959.5, 599.5 - 1000};
  corner.insert(corner.end(), distortion.begin(), distortion.end());
  strip.insert(strip.end(), distortion.begin(), distortion.end());
  const Rig rig({Camera("LENSMODEL_OPENCV8", corner, 640, 480), Camera("LENSMODEL_OPENCV8", strip, 1920, 200)},
                {"corner", "strip"}, {{"module0", 0, 1, Pose::FromRotationVector({0, -0.1047, 0}, {-90, 0, 5})}},
                {Pose::Identity()});
  const std::string path = ::testing::TempDir() + "/rig_windowed.yaml";
  WriteRigFile(rig, path);
  const Rig back = ReadRigFile(path);
  EXPECT_EQ(back.camera(0).intrinsics(), corner);
  EXPECT_EQ(back.camera(1).intrinsics(), strip);
}

TEST(RigFile, IsPlainYamlWithoutCustomTags) {
  const std::string text = RigToYaml(MakeRandomRig(1));
  EXPECT_EQ(text.find("!!"), std::string::npos);
  EXPECT_NE(text.find("format: stereorig-rig"), std::string::npos);
  EXPECT_NE(text.find("units: mm"), std::string::npos);
}

TEST(RigFile, AtomicWriteLeavesNoTemporaryFiles) {
  const std::string dir = ::testing::TempDir() + "/atomic_rig";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  WriteRigFile(MakeRandomRig(2), dir + "/rig.yaml");
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    ++n;
    EXPECT_EQ(e.path().filename(), "rig.yaml");
  }
  EXPECT_EQ(n, 1);
  // A missing folder is an input error, and nothing is created.
  EXPECT_THROW(WriteRigFile(MakeRandomRig(2), dir + "/missing/rig.yaml"), InputError);
}

}  // namespace
}  // namespace stereorig
