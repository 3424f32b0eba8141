#include "apps/reconstruct_json.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

// A cloud without a point has no error to report: its figures are null in
// JSON and "no point" on the console. They were 0, which read as a perfect
// score (score's merged |e| 0.0000 std 0.0000 of an empty cloud).
TEST(ReconstructJson, FiguresOfNoPointAreNullNotZero) {
  const ErrorFigures none;  // points 0
  const nlohmann::json j = ErrorFiguresJson(none);
  EXPECT_EQ(j["points"], 0);
  for (const char* key : {"mean_abs_mm", "mean_mm", "std_mm", "rms_mm", "p95_abs_mm", "max_abs_mm", "within_0_5_mm"})
    EXPECT_TRUE(j[key].is_null()) << key;
  EXPECT_EQ(ErrorText(none), "no point");

  ErrorFigures some;
  some.points = 3;
  some.mean_abs_mm = 0.0345;
  some.std_mm = 0.0443;
  EXPECT_DOUBLE_EQ(ErrorFiguresJson(some)["mean_abs_mm"].get<double>(), 0.0345);
  EXPECT_EQ(ErrorText(some), "|e| 0.0345 std 0.0443");
  // The same read back from the JSON (bench prints from its report).
  EXPECT_EQ(ErrorText(ErrorFiguresJson(some), " mm"), "|e| 0.0345 std 0.0443 mm");
  EXPECT_EQ(ErrorText(ErrorFiguresJson(none), " mm"), "no point");
}

}  // namespace
}  // namespace stereorig
