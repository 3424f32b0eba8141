// Runtime options: the hole-filling keys are read, defaulted and checked
// (a bad value or an unknown key is an InputError naming it).
#include "reconstruct/runtime_options.h"

#include <gtest/gtest.h>

#include <utility>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

TEST(RuntimeOptions, ReadsAndChecksTheFillKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("shape_model: ellipsoid\n", "defaults.yaml");
  EXPECT_TRUE(d.fill_follow_residuals);
  EXPECT_EQ(d.fill_residual_length_mm, 0.0);
  const RuntimeOptions o = ParseRuntimeOptions(
      "shape_model: ellipsoid\nfill_follow_residuals: false\nfill_residual_length_mm: 12.5\n", "set.yaml");
  EXPECT_FALSE(o.fill_follow_residuals);
  EXPECT_EQ(o.fill_residual_length_mm, 12.5);
  const std::pair<const char*, const char*> bad[] = {{"fill_residual_length_mm: 0.5\n", "fill_residual_length_mm"},
                                                     {"fill_residual_length_mm: -3\n", "fill_residual_length_mm"},
                                                     {"fill_follow_residuals: maybe\n", "fill_follow_residuals"},
                                                     {"fill_follow_residual: true\n", "fill_follow_residual"}};
  for (const auto& [text, key] : bad) {
    try {
      ParseRuntimeOptions(text, "bad.yaml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace stereorig
