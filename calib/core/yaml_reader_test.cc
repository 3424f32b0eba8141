#include "calib/core/yaml_reader.h"

#include <gtest/gtest.h>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

using testing::InputErrorMessage;

TEST(YamlMap, NamesFileAndKeyInEveryError) {
  YamlMap m = YamlMap::LoadString("a: 1\nb: [1, 2]\nc: {d: .nan}\ne: text\n", "f.yaml");
  EXPECT_EQ(m.GetDouble("a"), 1.0);
  EXPECT_EQ(InputErrorMessage([&] { m.GetDoubles("b", 3); }), "f.yaml: b: expected 3 numbers, got 2");
  EXPECT_EQ(InputErrorMessage([&] { m.GetMap("c").GetDouble("d"); }), "f.yaml: c.d: NaN or Inf is not allowed");
  EXPECT_EQ(InputErrorMessage([&] { m.GetDouble("e"); }), "f.yaml: e: expected a number, got 'text'");
  EXPECT_EQ(InputErrorMessage([&] { m.GetDouble("zz"); }), "f.yaml: zz: missing key");
}

TEST(YamlMap, FinishRejectsKeysNobodyRead) {
  YamlMap m = YamlMap::LoadString("known: 1\ntypo_key: 2\n", "f.yaml");
  m.GetInt("known");
  EXPECT_EQ(InputErrorMessage([&] { m.Finish(); }), "f.yaml: typo_key: unknown key");
  m.GetInt("typo_key");
  EXPECT_NO_THROW(m.Finish());
}

TEST(YamlMap, DefaultsCountAsRead) {
  YamlMap m = YamlMap::LoadString("x: 2\n", "f.yaml");
  EXPECT_EQ(m.GetDouble("y", 5.0), 5.0);
  EXPECT_EQ(m.GetInt("x", 3), 2);
  EXPECT_NO_THROW(m.Finish());
}

TEST(YamlMap, SyntaxErrorsAreInputErrors) {
  EXPECT_THROW(YamlMap::LoadString("a: [1, 2\n", "f.yaml"), InputError);
  EXPECT_THROW(YamlMap::LoadString("- just a list\n", "f.yaml"), InputError);
  EXPECT_THROW(YamlMap::LoadFile("/nonexistent/f.yaml"), InputError);
}

}  // namespace
}  // namespace stereorig
