// The interpolation of the skipped columns (skipped_columns.h) on hand-made
// rows; the matcher's clouds with it against the analytic truth are in
// matcher_test.cc (Matcher.SkippedColumns*).
#include "reconstruct/skipped_columns.h"

#include <gtest/gtest.h>

#include "reconstruct/disparity_state.h"

namespace stereorig {
namespace {

constexpr uint8_t kPoint = uint8_t(PixelStatus::kPoint);

TEST(SkippedColumns, RefinesTheFirstColumnAndEveryStepAfterIt) {
  EXPECT_TRUE(IsRefinedColumn(0, 1) && IsRefinedColumn(7, 1));
  EXPECT_TRUE(IsRefinedColumn(0, 3) && IsRefinedColumn(6, 3));
  EXPECT_FALSE(IsRefinedColumn(1, 3) || IsRefinedColumn(5, 3));
}

TEST(SkippedColumns, InterpolatesOnlyBetweenAcceptedNeighboursOnTheSlope) {
  // Columns 10 and 13 refined, 11 and 12 skipped; slope 0.1 px/px.
  float d[16] = {}, c[16] = {};
  uint8_t s[16] = {};
  d[10] = 40.0f, d[13] = 40.3f + 0.2f;  // 0.2 px off the slope's line: within kMaxSkippedColumnJumpPx
  c[10] = 0.9f, c[13] = 0.95f;
  s[10] = s[13] = kPoint;
  double out = 0;
  float conf = 0;
  ASSERT_TRUE(InterpolateSkippedColumn(d, c, s, 10, 11, 13, 0.1, &out, &conf));
  EXPECT_NEAR(out, 40.0 + 0.5 / 3, 1e-5);  // a third of the way
  EXPECT_FLOAT_EQ(conf, 0.9f);             // the lower of the two
  ASSERT_TRUE(InterpolateSkippedColumn(d, c, s, 10, 12, 13, 0.1, &out, &conf));
  EXPECT_NEAR(out, 40.0 + 2 * 0.5 / 3, 1e-5);
  // A step beyond the slope (a depth edge, a grid period): no value.
  d[13] = float(40.3 + kMaxSkippedColumnJumpPx + 0.05);
  EXPECT_FALSE(InterpolateSkippedColumn(d, c, s, 10, 11, 13, 0.1, &out, &conf));
  d[13] = 40.3f;
  EXPECT_TRUE(InterpolateSkippedColumn(d, c, s, 10, 11, 13, 0.1, &out, &conf));
  // A neighbour that was rejected (or never measured): no value, whatever
  // its disparity array holds.
  s[13] = uint8_t(PixelStatus::kLowZncc);
  EXPECT_FALSE(InterpolateSkippedColumn(d, c, s, 10, 11, 13, 0.1, &out, &conf));
  s[13] = kPoint, s[10] = uint8_t(PixelStatus::kNotSearched);
  EXPECT_FALSE(InterpolateSkippedColumn(d, c, s, 10, 11, 13, 0.1, &out, &conf));
}

}  // namespace
}  // namespace stereorig
