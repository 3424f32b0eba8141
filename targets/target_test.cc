#include "targets/target.h"

#include <gtest/gtest.h>

#include "calib/core/input_error.h"
#include "targets/target_file.h"

namespace stereorig {
namespace {

TEST(Target, CornersLieOnTheSquareGridOfTheFaceFrame) {
  const Target t = DefaultTarget();
  EXPECT_EQ(t.num_corners(), 99);
  EXPECT_EQ(t.CornerInFace(0), Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(t.CornerInFace(12), Eigen::Vector3d(9, 9, 0));  // row 1, col 1
  // Around each inner corner the four squares alternate black and white.
  for (int id : {0, 17, 98}) {
    const Eigen::Vector3d c = t.CornerInFace(id);
    const double e = 0.25 * t.square_size_mm();
    const bool a = t.IsBlack(Face::kFront, c.x() - e, c.y() - e), b = t.IsBlack(Face::kFront, c.x() + e, c.y() - e);
    const bool d = t.IsBlack(Face::kFront, c.x() + e, c.y() + e), g = t.IsBlack(Face::kFront, c.x() - e, c.y() + e);
    EXPECT_NE(a, b);
    EXPECT_EQ(a, d);
    EXPECT_EQ(b, g);
  }
}

TEST(Target, IdealBackFromFrontMapsEachBackCornerThroughThePlate) {
  const double thickness = 5.0;
  const Pose back_from_front = IdealBackFromFront(11, 9.0, thickness);
  const Pose front_from_back = back_from_front.Inverse();
  // Back corner 0 (top-left seen from behind) is behind front corner 10
  // (top-right seen from the front), one plate thickness deep.
  const Eigen::Vector3d p = front_from_back * Eigen::Vector3d(0, 0, 0);
  EXPECT_LT((p - Eigen::Vector3d(90, 0, thickness)).norm(), 1e-12);
  // A half turn: the two faces' normals (z into the board) are opposite.
  EXPECT_NEAR(back_from_front.AngleDeg(), 180.0, 1e-9);
}

TEST(Target, TagsIdentifyTheirFaceAndAreDisjoint) {
  const Target t = DefaultTarget();
  Face f;
  ASSERT_TRUE(t.FaceOfTag(3, &f));
  EXPECT_EQ(f, Face::kFront);
  ASSERT_TRUE(t.FaceOfTag(104, &f));
  EXPECT_EQ(f, Face::kBack);
  EXPECT_FALSE(t.FaceOfTag(50, &f));
  // A tag's black border is black, and the white quiet zone around it is white.
  const TagPlacement* tag = t.FindTag(Face::kFront, 0);
  ASSERT_NE(tag, nullptr);
  const double half = 0.5 * t.layout().tag_size_mm;
  EXPECT_TRUE(t.IsBlack(Face::kFront, tag->center_x_mm - half + 0.1, tag->center_y_mm));
  EXPECT_FALSE(t.IsBlack(Face::kFront, tag->center_x_mm - half - 0.1, tag->center_y_mm));
}

TEST(Target, RejectsBadLayouts) {
  Target::Layout l = DefaultTarget().layout();
  l.faces[1].tags[0].id = l.faces[0].tags[0].id;  // shared ID
  EXPECT_THROW(Target(l, "t"), InputError);
  l = DefaultTarget().layout();
  l.faces[0].tags[0].center_y_mm = 20;  // on the squares
  EXPECT_THROW(Target(l, "t"), InputError);
  l = DefaultTarget().layout();
  l.tag_family = "tag99h99";
  EXPECT_THROW(Target(l, "t"), InputError);
  l = DefaultTarget().layout();
  l.square_size_mm = -1;
  EXPECT_THROW(Target(l, "t"), InputError);
  // Two tags of a face printed over each other (11 mm tags 5 mm apart, both
  // in the top margin), or touching (11 mm apart: detection then misses
  // them), and, accepted, an eighth of a tag between their borders.
  for (const double apart_mm : {5.0, 11.0, 12.37}) {
    l = DefaultTarget().layout();
    l.faces[0].tags[1].center_x_mm = l.faces[0].tags[0].center_x_mm + apart_mm;
    try {
      Target(l, "t");
      ADD_FAILURE() << "tags " << apart_mm << " mm apart accepted";
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(),
                   "t: tags 0 and 1 are too close: their centres must be at least tag_size_mm + 1/8 of it (12.4 mm) "
                   "apart along x or y, for the white between them");
    }
  }
  l.faces[0].tags[1].center_x_mm = l.faces[0].tags[0].center_x_mm + 11 * 9.0 / 8;
  EXPECT_NO_THROW(Target(l, "t"));
}

TEST(TargetFile, RoundTripsExactlyAndRejectsUnknownKeys) {
  const Target t = DefaultTarget();
  const std::string text = TargetToYaml(t);
  const Target back = ParseTargetYaml(text, "t.yaml");
  EXPECT_EQ(TargetToYaml(back), text);
  EXPECT_EQ(back.back_from_front().ToMatrix4(), t.back_from_front().ToMatrix4());
  EXPECT_THROW(ParseTargetYaml(text + "colour: red\n", "t.yaml"), InputError);
  const Target plain = PlainTarget(9, 6, 25.0);
  const Target plain_back = ParseTargetYaml(TargetToYaml(plain), "p.yaml");
  EXPECT_FALSE(plain_back.double_sided());
  EXPECT_EQ(plain_back.num_corners(), 54);
}

// A square size typed in metres (9 mm as 0.009) is named as such, at the
// value and the unit, not as tags off the margin (their placement is in mm,
// against squares of 9 um). The smallest square accepted is 1 mm.
TEST(TargetFile, ASquareSizeInMetresIsNamedAsSuch) {
  std::string text = TargetToYaml(DefaultTarget());
  const std::string key = "square_size_mm: 9\n";
  ASSERT_NE(text.find(key), std::string::npos) << text;
  text.replace(text.find(key), key.size(), "square_size_mm: 0.009\n");
  try {
    ParseTargetYaml(text, "t_m.yaml");
    ADD_FAILURE() << "squares of 9 um accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "t_m.yaml: square_size_mm 0.009: squares of 9 um, under the 1 mm a camera resolves; is it in "
                 "metres? the unit is mm");
  }
  // 0.9 in metres would be squares of 900 mm; in centimetres, of 9 mm.
  try {
    PlainTarget(9, 6, 0.9);
    ADD_FAILURE() << "squares of 900 um accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "plain target: square_size_mm 0.9: squares of 900 um, under the 1 mm a camera resolves; is it in "
                 "centimetres? the unit is mm");
  }
  EXPECT_NO_THROW(PlainTarget(9, 6, 1.0));
  EXPECT_THROW(PlainTarget(9, 6, 0.999), InputError);
}

}  // namespace
}  // namespace stereorig
