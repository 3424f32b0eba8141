#include "calib/layout_file.h"

#include <gtest/gtest.h>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

TEST(LayoutFile, ReadsModulesAndFaces) {
  const auto m = ParseLayoutYaml(
      "modules:\n  - {name: module0, left: 0, right: 1}\n  - {name: module1, left: 2, right: 3, face: back}\n", "t");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].name, "module0");
  EXPECT_EQ(m[1].left_camera, 2);
  EXPECT_EQ(m[1].right_camera, 3);
  EXPECT_FALSE(m[0].face.has_value());
  ASSERT_TRUE(m[1].face.has_value());
  EXPECT_EQ(*m[1].face, Face::kBack);
}

TEST(LayoutFile, RejectsBadInput) {
  EXPECT_THROW(ParseLayoutYaml("modules:\n  - {name: m, left: 0, right: 1, fcae: back}\n", "t"), InputError);
  EXPECT_THROW(ParseLayoutYaml("modules:\n  - {name: m, left: 0, right: 1, face: side}\n", "t"), InputError);
  EXPECT_THROW(ParseLayoutYaml("modules:\n  - {name: m, left: 1, right: 1}\n", "t"), InputError);
  EXPECT_THROW(ParseLayoutYaml("modules: []\n", "t"), InputError);
  EXPECT_THROW(ParseLayoutYaml("modules:\n  - {name: m, left: 0, right: 1}\nextra: 1\n", "t"), InputError);
}

// A camera in two modules, or a camera number left out, is named when the
// file is read (calibrate used to find it only after detecting every image).
TEST(LayoutFile, EachCameraIsInExactlyOneModule) {
  EXPECT_EQ(testing::InputErrorMessage([] {
              ParseLayoutYaml("modules:\n  - {name: a, left: 0, right: 1}\n  - {name: b, left: 1, right: 2}\n", "t");
            }),
            "t: modules[1]: camera 1 is already in module a: each camera belongs to exactly one module");
  EXPECT_EQ(testing::InputErrorMessage([] {
              ParseLayoutYaml("modules:\n  - {name: a, left: 0, right: 1}\n  - {name: b, left: 3, right: 4}\n", "t");
            }),
            "t: modules: camera 2 is in no module, though camera 4 is: cameras are numbered 0.. without gaps, each in "
            "one module");
  EXPECT_NO_THROW(
      ParseLayoutYaml("modules:\n  - {name: a, left: 2, right: 3}\n  - {name: b, left: 1, right: 0}\n", "t"));
}

// Two modules of one name were read, and calibrate wrote a rig of two
// "module0" (exit 0): reports and the rig file tell modules apart by name.
TEST(LayoutFile, EachModuleNameIsUsedOnce) {
  EXPECT_EQ(testing::InputErrorMessage([] {
              ParseLayoutYaml(
                  "modules:\n  - {name: module0, left: 0, right: 1}\n  - {name: module0, left: 2, right: 3}\n", "t");
            }),
            "t: modules[1].name: module0 is used twice (modules[0] too): each module needs a name of its own");
}

// An empty name tells no module apart, yet was accepted.
TEST(LayoutFile, AnEmptyModuleNameIsRefused) {
  EXPECT_EQ(testing::InputErrorMessage([] { ParseLayoutYaml("modules:\n  - {name: \"\", left: 0, right: 1}\n", "t"); }),
            "t: modules[0].name: is empty: each module needs a name of its own");
}

}  // namespace
}  // namespace stereorig
