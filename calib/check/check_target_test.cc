// Which board the nightly check measures with (check_target.h): the rig
// file's record of the calibration's board, against tonight's target file.
#include "calib/check/check_target.h"

#include <gtest/gtest.h>

#include "calib/core/input_error.h"
#include "datasets/default_rig.h"

namespace stereorig {
namespace {

// The default board with its back_from_front moved by `t_mm` (a re-measured
// plate), or at another size.
Target Board(const Eigen::Vector3d& t_mm = Eigen::Vector3d::Zero(), int corners_x = 11, int corners_y = 9,
             double square_mm = 9.0) {
  Target::Layout layout = DoubleSidedTarget(corners_x, corners_y, square_mm).layout();
  layout.back_from_front = Pose(Eigen::Matrix3d::Identity(), t_mm) * layout.back_from_front;
  return Target(layout, "board");
}

// The default rig, calibrated with the default board, stage 3 having moved
// its back_from_front by 0.02 mm along x.
Rig CalibratedRig() {
  Rig rig = MakeDefaultRig().rig;
  rig.provenance().target = CalibrationTarget{
      "lab/board.yaml",         11, 9, 9.0, true, Board(Eigen::Vector3d(0.02, 0, 0)).back_from_front(),
      Board().back_from_front()};
  return rig;
}

std::string Refusal(const Rig& rig, const Target& file) {
  try {
    TargetForCheck(rig, file, "tonight/board.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CheckTarget, UsesTheBackFromFrontAsCalibrated) {
  const Rig rig = CalibratedRig();
  const CheckTarget used = TargetForCheck(rig, Board(), "tonight/board.yaml");
  EXPECT_TRUE(used.as_calibrated);
  EXPECT_TRUE(used.back_from_front_as_calibrated);
  EXPECT_EQ(used.file_vs_filed_mm, 0.0);
  EXPECT_EQ(used.calibrated_with, "lab/board.yaml");
  EXPECT_EQ(used.target.back_from_front().ToMatrix4(), rig.provenance().target->back_from_front.ToMatrix4());
  EXPECT_NEAR(used.calibrated_vs_file_mm, 0.02, 1e-12);
  EXPECT_NEAR(used.calibrated_vs_file_deg, 0.0, 1e-9);
  EXPECT_TRUE(used.note.empty()) << used.note;
  // Everything else is the file's: corners, tags, sigma.
  EXPECT_EQ(used.target.num_corners(), 99);
  EXPECT_EQ(used.target.layout().faces[1].tags.size(), Board().layout().faces[1].tags.size());
  EXPECT_EQ(used.target.back_from_front_sigma(), Board().back_from_front_sigma());
}

TEST(CheckTarget, ARigFileWithoutARecordUsesTheFileAndSaysSo) {
  Rig rig = CalibratedRig();
  rig.provenance().target.reset();
  const Target file = Board(Eigen::Vector3d(0, 0, 0.01));
  const CheckTarget used = TargetForCheck(rig, file, "tonight/board.yaml");
  EXPECT_FALSE(used.as_calibrated);
  EXPECT_TRUE(used.calibrated_with.empty());
  EXPECT_EQ(used.target.back_from_front().ToMatrix4(), file.back_from_front().ToMatrix4());
  EXPECT_NE(used.note.find("records no calibration target"), std::string::npos) << used.note;
}

// The plate re-measured (0.01 mm, its stated 1 sigma per axis) is the
// plate calibrated with: measured with the calibration's estimate, said; a
// change no print shows (1e-6 mm) is not said.
TEST(CheckTarget, ARemeasuredPlateIsMeasuredAsCalibratedAndSaid) {
  const Rig rig = CalibratedRig();
  const CheckTarget used = TargetForCheck(rig, Board(Eigen::Vector3d(0, 0, 0.01)), "tonight/board.yaml");
  EXPECT_TRUE(used.as_calibrated);
  EXPECT_TRUE(used.back_from_front_as_calibrated);
  EXPECT_EQ(used.target.back_from_front().ToMatrix4(), rig.provenance().target->back_from_front.ToMatrix4());
  EXPECT_NEAR(used.file_vs_filed_mm, 0.01, 1e-12);
  EXPECT_NE(used.note.find("0.0100 mm and 0.0000 deg from the one filed when the rig was calibrated, within 3"),
            std::string::npos)
      << used.note;
  EXPECT_NE(used.note.find("the same plate re-measured"), std::string::npos) << used.note;
  const CheckTarget tiny = TargetForCheck(rig, Board(Eigen::Vector3d(1e-6, 0, 0)), "tonight/board.yaml");
  EXPECT_TRUE(tiny.back_from_front_as_calibrated);
  EXPECT_TRUE(tiny.note.empty()) << tiny.note;
}

// Another plate of the same print (0.5 mm thicker, 50 of its stated sigma;
// a user's walkthrough: measured with the calibration's estimate, every
// camera and the closure read as changed): measured with its file's, said.
// Just beyond 3 sigma on one axis (0.031 mm) is another plate too.
TEST(CheckTarget, AnotherPlateIsMeasuredWithItsFile) {
  const Rig rig = CalibratedRig();
  for (const Eigen::Vector3d& t : {Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0.031, 0, 0)}) {
    const Target file = Board(t);
    const CheckTarget used = TargetForCheck(rig, file, "tonight/board.yaml");
    EXPECT_TRUE(used.as_calibrated);
    EXPECT_FALSE(used.back_from_front_as_calibrated);
    EXPECT_EQ(used.target.back_from_front().ToMatrix4(), file.back_from_front().ToMatrix4());
    EXPECT_EQ(used.calibrated_vs_file_mm, 0.0);
    EXPECT_NEAR(used.file_vs_filed_mm, t.norm(), 1e-12);
    EXPECT_NE(used.note.find("beyond 3 of its stated sigma: another plate? measured with the target file's"),
              std::string::npos)
        << used.note;
  }
  // A plate whose sigma says it is held (0) has no room: any change is another plate.
  Target::Layout held = Board().layout();
  held.back_from_front_sigma.setZero();
  held.back_from_front = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.001, 0, 0)) * held.back_from_front;
  EXPECT_FALSE(TargetForCheck(rig, Target(held, "held"), "tonight/board.yaml").back_from_front_as_calibrated);
}

// Another board is refused, naming both boards, the target file, the rig
// file and the record's file: other corners, sides, or squares more than
// 0.5 % off. The same board's squares re-measured (0.01 %) are measured
// with the record's size, on which the rig's scale rests, and said; a
// digit more in print (9.000000000001) is not said.
TEST(CheckTarget, AnotherBoardIsRefused) {
  const Rig rig = CalibratedRig();
  const CheckTarget printed = TargetForCheck(rig, Board(Eigen::Vector3d::Zero(), 11, 9, 9.000000000001), "t.yaml");
  EXPECT_EQ(printed.target.square_size_mm(), 9.0);
  EXPECT_TRUE(printed.note.empty()) << printed.note;
  const CheckTarget remeasured = TargetForCheck(rig, Board(Eigen::Vector3d::Zero(), 11, 9, 9.0009), "t.yaml");
  EXPECT_EQ(remeasured.target.square_size_mm(), 9.0);
  EXPECT_NE(remeasured.note.find("the target file's squares are 9.0009 mm, the rig was calibrated with 9 mm"),
            std::string::npos)
      << remeasured.note;
  EXPECT_EQ(Refusal(rig, Board(Eigen::Vector3d::Zero(), 11, 9, 9.0449)), "");  // 0.499 %
  struct Case {
    Target file;
    const char* says;
  };
  const Case cases[] = {{Board(Eigen::Vector3d::Zero(), 11, 9, 9.18), "11x9 inner corners of 9.18 mm, double-sided"},
                        {Board(Eigen::Vector3d::Zero(), 11, 9, 9.0451), "11x9 inner corners of 9.0451 mm"},
                        {Board(Eigen::Vector3d::Zero(), 11, 9, 8.9549), "11x9 inner corners of 8.9549 mm"},
                        {Board(Eigen::Vector3d::Zero(), 12, 9, 9.0), "12x9 inner corners of 9 mm"},
                        {Board(Eigen::Vector3d::Zero(), 11, 8, 9.0), "11x8 inner corners of 9 mm"},
                        {PlainTarget(11, 9, 9.0), "11x9 inner corners of 9 mm, one-sided"}};
  for (const Case& c : cases) {
    const std::string e = Refusal(rig, c.file);
    EXPECT_EQ(e.rfind("tonight/board.yaml: a board of ", 0), 0u) << e;
    EXPECT_NE(e.find(c.says), std::string::npos) << e;
    EXPECT_NE(e.find(rig.Where() + " was calibrated with one of 11x9 inner corners of 9 mm, double-sided"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("from lab/board.yaml"), std::string::npos) << e;
  }
}

// A one-sided board has no back_from_front to take: the file's board as it is.
TEST(CheckTarget, AOneSidedBoardIsTakenAsItIs) {
  Rig rig = CalibratedRig();
  rig.provenance().target->double_sided = false;
  const Target plain = PlainTarget(11, 9, 9.0);
  const CheckTarget used = TargetForCheck(rig, plain, "tonight/board.yaml");
  EXPECT_TRUE(used.as_calibrated);
  EXPECT_FALSE(used.target.double_sided());
  EXPECT_EQ(used.calibrated_vs_file_mm, 0.0);
  EXPECT_TRUE(used.note.empty()) << used.note;
}

}  // namespace
}  // namespace stereorig
