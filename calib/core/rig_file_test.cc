#include "calib/core/rig_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"
#include "calib/core/number_text.h"

namespace stereorig {
namespace {

using testing::InputErrorMessage;

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
                      {{"stage1_rms_px", 1.1 + u(rng)}},  // an RMS, >= 0 (the reader refuses less)
                      {{"S_0_1_mm", 1e-3 * (2 + u(rng))}},
                      std::nullopt};
  if (seed % 2) {  // half of them record the board they were calibrated with
    CalibrationTarget t;
    t.file = "boards/\"plate 7\".yaml";
    t.corners_x = 11;
    t.corners_y = 9;
    t.square_size_mm = 9 + 1e-3 * u(rng);
    t.double_sided = seed % 4 == 1;
    t.back_from_front_file = Pose::FromRotationVector({0, M_PI, 0}, {90, 0, 5});
    t.back_from_front = Pose::FromRotationVector({1e-4 * u(rng), M_PI + 1e-4 * u(rng), 1e-4 * u(rng)},
                                                 {90 + 0.01 * u(rng), 0.01 * u(rng), 5 + 0.01 * u(rng)});
    for (int k = 0; k < 6; ++k) t.back_from_front_sigma_file(k) = 0.01 + 1e-3 * u(rng);
    rig.provenance().target = t;
  }
  return rig;
}

// Files people read hold the numbers they would type: 38.1, not %.17g's
// 38.100000000000001 (the simulator's certificates read so), and the text
// still reads back as the very same double.
TEST(RigFile, DoublesAreWrittenAsTheShortestTextThatReadsBackTheSame) {
  EXPECT_EQ(FormatDouble(38.1), "38.1");
  EXPECT_EQ(FormatDouble(25.4), "25.4");
  EXPECT_EQ(FormatDouble(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(FormatDouble(-1e-17), "-1e-17");
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1000, 1000);
  for (int k = 0; k < 1000; ++k) {
    const double x = u(rng) * std::pow(10.0, k % 40 - 20);
    EXPECT_EQ(std::strtod(FormatDouble(x).c_str(), nullptr), x) << FormatDouble(x);
  }
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
    ASSERT_EQ(back.provenance().target.has_value(), rig.provenance().target.has_value()) << seed;
    if (const auto& t = rig.provenance().target) {
      const CalibrationTarget& b = *back.provenance().target;
      EXPECT_EQ(b.file, t->file);
      EXPECT_EQ(b.corners_x, t->corners_x);
      EXPECT_EQ(b.corners_y, t->corners_y);
      EXPECT_EQ(b.square_size_mm, t->square_size_mm);
      EXPECT_EQ(b.double_sided, t->double_sided);
      EXPECT_EQ(b.back_from_front.ToMatrix4(), t->back_from_front.ToMatrix4());
      EXPECT_EQ(b.back_from_front_file.ToMatrix4(), t->back_from_front_file.ToMatrix4());
      EXPECT_EQ(b.back_from_front_sigma_file, t->back_from_front_sigma_file);
    }
  }
}

// A rotation copied by hand with 8 significant digits (a user's
// right_from_left: max |R^T R - I| 1e-9, just over the 1e-9 a written file
// meets) is read, made orthonormal again; one off by 4.5e-5 (wrong numbers,
// not rounding) is refused, the deviation and the tolerance printed (it
// printed "max |R^T R - I| = 0.000000").
TEST(RigFile, ARotationTypedWithEightDigitsIsReadAndAWrongOneRefused) {
  const Rig rig = MakeRandomRig(0);
  const std::string text = RigToYaml(rig);
  const Eigen::Matrix4d m = rig.module(0).right_from_left.ToMatrix4();
  const size_t line = text.find("right_from_left: [[");
  ASSERT_NE(line, std::string::npos) << text;
  // The rig file as written, module 0's rotation typed as `typed` (its
  // elements replaced in the order they are printed, row by row).
  auto with = [&](const Eigen::Matrix4d& typed) {
    std::string t = text;
    size_t at = line;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        const std::string was = FormatDouble(m(r, c)), now = FormatDouble(typed(r, c));
        at = t.find(was, at);
        t.replace(at, was.size(), now);
        at += now.size();
      }
    return t;
  };
  Eigen::Matrix4d eight = m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) eight(r, c) = std::stod(NumberText(m(r, c), 8));
  std::string why;
  ASSERT_FALSE(IsRigid(eight, 1e-9, &why)) << "8 digits must miss the strict tolerance for this test";
  const Rig back = ParseRigYaml(with(eight), "rig_8dig.yaml");
  const Eigen::Matrix3d r = back.module(0).right_from_left.rotation();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  // The nearest rotation: within the typed digits' rounding (5e-9 on 0.1).
  EXPECT_LT((r - m.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-8);
  // Six digits, the fewest the reader promises (typed_pose.h's bound):
  // read, and as near the rotation as the digits are.
  Eigen::Matrix4d six = m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) six(r, c) = std::stod(NumberText(m(r, c), 6));
  const Eigen::Matrix3d r6 = ParseRigYaml(with(six), "rig_6dig.yaml").module(0).right_from_left.rotation();
  EXPECT_LT((r6 - m.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-6);
  Eigen::Matrix4d wrong = m;
  wrong(0, 0) += 4.5e-5 / 2;  // |R^T R - I| grows by twice the change
  try {
    ParseRigYaml(with(wrong), "rig_nonortho.yaml");
    ADD_FAILURE() << "a rotation 4.5e-5 off orthonormal accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "rig_nonortho.yaml: modules[0].right_from_left: rotation is not orthonormal (max |R^T R - I| = "
                 "4.5e-05, over the 2e-06 allowed)");
  }
}

// provenance.target is optional (a rig file written before it was, and the
// simulator's truth, have none), but when present every key is required
// and checked, each error naming the key.
TEST(RigFile, TheCalibrationTargetIsOptionalAndCheckedWhenPresent) {
  Rig rig = MakeRandomRig(1);
  ASSERT_TRUE(rig.provenance().target.has_value());
  const std::string with = RigToYaml(rig);
  rig.provenance().target.reset();
  const std::string without = RigToYaml(rig);
  ASSERT_EQ(without.find("  target:"), std::string::npos);
  EXPECT_FALSE(ParseRigYaml(without, "old.yaml").provenance().target.has_value());
  // A version 1 file (before the record) reads; one with a record is not one.
  ASSERT_NE(without.find("version: 2\n"), std::string::npos);
  std::string v1 = without;
  v1.replace(v1.find("version: 2\n"), 11, "version: 1\n");
  EXPECT_FALSE(ParseRigYaml(v1, "v1.yaml").provenance().target.has_value());
  std::string v1_with = with;
  v1_with.replace(v1_with.find("version: 2\n"), 11, "version: 1\n");
  try {
    ParseRigYaml(v1_with, "v1.yaml");
    ADD_FAILURE() << "a version 1 file with provenance.target was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("v1.yaml: provenance.target: is not in a version 1 rig file"),
              std::string::npos)
        << e.what();
  }
  ASSERT_TRUE(ParseRigYaml(with, "new.yaml").provenance().target.has_value());
  auto edited = [&](const std::string& from, const std::string& to) {
    const size_t at = with.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    std::string s = with;
    return at == std::string::npos ? s : s.replace(at, from.size(), to);
  };
  const std::string square = "    square_size_mm: ";
  const std::string square_line =
      with.substr(with.find(square), with.find('\n', with.find(square)) + 1 - with.find(square));
  const std::pair<std::string, std::string> bad[] = {
      {"    corners_x: 11\n", "    corners_x: 1\n"},
      {"    corners_y: 9\n", ""},
      {square_line, square + "0\n"},
      {square_line, square + "-9\n"},
      {"    double_sided: true\n", "    double_sided: maybe\n"},
      {"    back_from_front: [[", "    back_from_front: [[2, "},
      {"    file: ", "    colour: \"red\"\n    file: "},
      {"    back_from_front_sigma_file: [", "    back_from_front_sigma_file: [-1, "},
  };
  const char* key[] = {"provenance.target.corners_x",      "provenance.target.corners_y",
                       "provenance.target.square_size_mm", "provenance.target.square_size_mm",
                       "provenance.target.double_sided",   "provenance.target.back_from_front",
                       "provenance.target.colour",         "provenance.target.back_from_front_sigma_file"};
  for (size_t i = 0; i < std::size(bad); ++i) {
    try {
      ParseRigYaml(edited(bad[i].first, bad[i].second), "rig.yaml");
      ADD_FAILURE() << "accepted: " << bad[i].second;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key[i]), std::string::npos) << e.what();
    }
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

// A translation typed in metres (a 90 mm baseline as 0.09) was read as a
// module of 0.09 mm baseline (stereorig rig: "baseline 0.0900 mm", exit 0).
// A baseline, or two modules' distance in S, under 1 mm is refused naming
// the key, the value and the unit; 1 mm is read.
TEST(RigFile, ABaselineOrModulesDistanceUnderOneMillimetreIsRefused) {
  const Rig rig = MakeRandomRig(0);
  // `rig` with module 0's right_from_left and S[0][1] translated by the two,
  // as its file reads.
  auto read_with = [&](const Eigen::Vector3d& baseline_mm, const Eigen::Vector3d& module0_to_1_mm) {
    std::vector<StereoModule> modules = rig.modules();
    modules[0].right_from_left = Pose(modules[0].right_from_left.rotation(), baseline_mm);
    const Rig edited(rig.cameras(), rig.camera_names(), modules,
                     {Pose::Identity(), Pose(rig.S(0, 1).rotation(), module0_to_1_mm)});
    return ParseRigYaml(RigToYaml(edited), "rig.yaml");
  };
  const Eigen::Vector3d s_mm(0, 0, 400);
  EXPECT_EQ(InputErrorMessage([&] {
              read_with({-0.09, 0, 0}, s_mm);
            }),
            "rig.yaml: modules[0].right_from_left: baseline 0.09 mm, under the 1 mm two cameras' centres stand apart "
            "at the least; is it in metres? the unit is mm");
  EXPECT_EQ(InputErrorMessage([&] {
              read_with({0, 0, 0}, s_mm);
            }),
            "rig.yaml: modules[0].right_from_left: baseline 0 mm, under the 1 mm two cameras' centres stand apart at "
            "the least: they share one centre");
  EXPECT_EQ(InputErrorMessage([&] {
              read_with({-90, 0, 5}, s_mm / 1000);
            }),
            "rig.yaml: S[0][1]: modules 0 and 1 stand 0.4 mm apart, under the 1 mm two cameras' centres stand "
            "apart at the least; is it in metres? the unit is mm");
  EXPECT_EQ(InputErrorMessage([&] {
              read_with({-0.999, 0, 0}, s_mm);
            }).substr(0, 60),
            "rig.yaml: modules[0].right_from_left: baseline 0.999 mm, und");
  EXPECT_EQ(read_with({-1, 0, 0}, {0, 0, 1}).module(0).right_from_left.DistanceMm(), 1.0);
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
