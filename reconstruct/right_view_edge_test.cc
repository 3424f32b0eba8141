// The right view's edge: the rule on constructed maps (exact), and the
// matcher on an analytically rendered plane whose right image ends in a zero
// fill, against its true disparity.
#include "reconstruct/right_view_edge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "calib/core/input_error.h"
#include "reconstruct/disparity_state_testing.h"
#include "reconstruct/matcher.h"
#include "reconstruct/runtime_options.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

using testing::StateOf;

// Right columns < 100 without data; the default acceptance: half period 4
// px, window half width 4, so at slope 0 a pixel is in the zone when
// floor(x - d - 12) < 100 (or its columns leave the 300 px image), at slope
// 0.5 (period 4 px) when floor(x - d - 8) < 100. A surface at d = 20 fills
// the map; islands at d = 30 (not joined to it: 10 px > 1 px):
//   A x 120-130, y 10-20: x - d 90-100, all in the zone: dropped (121);
//   B x 135-160, y 25-30: reaches x >= 142, out of the zone: kept;
//   C x 2-8, y 35-38: x - d < 0, the image's own edge: dropped (28);
//   D x 136-139, y 40-43, slope 0.5: x = 138, 139 out of the zone: kept;
//   D' the same at slope 0, y 45-48: all in the zone: dropped (16).
// The surface at d = 20 is in the zone for x < 132 and continues: kept.
// Exact: no tolerance.
TEST(RightViewEdge, DropsExactlyTheComponentsWhollyInTheZone) {
  cv::Mat valid(50, 300, CV_8UC1, cv::Scalar(255));
  valid(cv::Rect(0, 0, 100, 50)).setTo(0);
  cv::Mat disparity(50, 300, CV_32FC1, cv::Scalar(20.0f));
  const cv::Rect a(120, 10, 11, 11), b(135, 25, 26, 6), c(2, 35, 7, 4), d(136, 40, 4, 4), d0(136, 45, 4, 4);
  for (const cv::Rect& r : {a, b, c, d, d0}) disparity(r).setTo(30.0f);
  DisparityState s = StateOf(disparity);
  s.slope_x(d).setTo(0.5f);
  const cv::Rect roi(0, 0, 300, 50);
  const RefineAcceptance accept;
  ASSERT_EQ(accept.half_period_px, 4);
  ASSERT_EQ(accept.subpixel.half_width_px, 4);
  EXPECT_EQ(DropUnverifiableAtRightViewEdge(valid, accept, 1.0, roi, &s), 121 + 28 + 16);
  for (int y = 0; y < 50; ++y)
    for (int x = 0; x < 300; ++x) {
      const cv::Point p(x, y);
      const bool dropped_expected = a.contains(p) || c.contains(p) || d0.contains(p);
      const bool dropped = !std::isfinite(s.disparity_px.at<float>(y, x));
      ASSERT_EQ(dropped, dropped_expected) << x << " " << y;
      EXPECT_EQ(s.status.at<uint8_t>(y, x), uint8_t(dropped ? PixelStatus::kRightViewEdge : PixelStatus::kPoint));
      EXPECT_EQ(s.confidence.at<float>(y, x), dropped ? 0.0f : 0.9f);
    }
  // Without a mask only the image's own columns bound the view: island C.
  DisparityState image_only = StateOf(disparity);
  image_only.slope_x(d).setTo(0.5f);
  EXPECT_EQ(DropUnverifiableAtRightViewEdge(cv::Mat(), accept, 1.0, roi, &image_only), 28);
  // Joined to the surface (a step within max_step_px), island A continues
  // out of the zone: nothing goes.
  DisparityState joined = StateOf(disparity);
  joined.slope_x(d).setTo(0.5f);
  joined.disparity_px(a).setTo(20.5f);
  joined.disparity_px(c).setTo(20.5f);
  joined.disparity_px(d0).setTo(20.5f);
  EXPECT_EQ(DropUnverifiableAtRightViewEdge(valid, accept, 1.0, roi, &joined), 0);
}

struct EdgeCounts {
  int off_1px = 0;          // valid pixels more than 1 px from the truth
  int near_edge = 0;        // valid pixels whose true match lies 0-16 columns inside the right view
  int right_view_edge = 0;  // pixels with that status
};

EdgeCounts Count(const MatchResult& m, const SyntheticPair& pair, int edge_x, int margin) {
  EdgeCounts c;
  for (int y = margin; y < pair.left.rows - margin; ++y)
    for (int x = margin; x < pair.left.cols - margin; ++x) {
      c.right_view_edge += m.status.at<uint8_t>(y, x) == uint8_t(PixelStatus::kRightViewEdge);
      const float d = m.disparity_px.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const double truth = pair.true_disparity_px.at<double>(y, x), xr = x - truth;
      c.off_1px += std::abs(d - truth) > 1;
      c.near_edge += xr >= edge_x && xr < edge_x + 16;
    }
  return c;
}

// The matcher tests' slanted plane (d = 40 + 0.04 x + 0.015 y) whose right
// image has no data left of column 120, as a rectified right view past its
// sensor's edge. Its pixels in the zone (true match within ~16 columns of
// the edge) belong to the plane, which continues out of it: the test must
// cost none of them, and change nothing else (the same points, to the
// float). 3 390 points lie within those 16 columns.
TEST(RightViewEdge, TheMatcherKeepsAPlaneTheRightViewsEdgeCuts) {
  SyntheticPairSpec spec;
  SyntheticPair pair = RenderSyntheticPair(spec);
  const int edge_x = 120;
  pair.right(cv::Rect(0, 0, edge_x, spec.height)).setTo(0);
  MatchOptions o;
  o.min_disparity_px = 24;
  o.num_disparities = 64;
  o.right_valid = cv::Mat(pair.right.size(), CV_8UC1, cv::Scalar(255));
  o.right_valid(cv::Rect(0, 0, edge_x, spec.height)).setTo(0);
  const int margin = 12;  // the image border: windows undefined there (matcher_test.cc)
  o.right_view_edge_test = false;
  const MatchResult without_test = Match(pair.left, pair.right, o);
  o.right_view_edge_test = true;
  const MatchResult with_test = Match(pair.left, pair.right, o);
  const EdgeCounts without = Count(without_test, pair, edge_x, margin), with = Count(with_test, pair, edge_x, margin);
  std::printf("points whose true match is 0-16 columns inside the right view: %d without the test, %d with\n",
              without.near_edge, with.near_edge);
  EXPECT_GT(without.near_edge, 3000);
  EXPECT_EQ(with.near_edge, without.near_edge);
  EXPECT_EQ(with.off_1px, without.off_1px);
  EXPECT_EQ(with.right_view_edge, 0);
  EXPECT_EQ(cv::norm(with_test.disparity_px != without_test.disparity_px, cv::NORM_L1), 0.0);
}

TEST(RightViewEdge, TheOptionIsReadAndOnByDefault) {
  EXPECT_TRUE(RuntimeOptions{}.match.right_view_edge_test);
  EXPECT_FALSE(ParseRuntimeOptions("match:\n  right_view_edge_test: false\n", "test").match.right_view_edge_test);
  EXPECT_THROW(ParseRuntimeOptions("match:\n  right_view_edge_test: sometimes\n", "test"), InputError);
}

}  // namespace
}  // namespace stereorig
