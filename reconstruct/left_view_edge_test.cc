// The left view's own edge: the rule on a constant map (exact), and the
// matcher on an analytically rendered plane whose left image ends in a
// zero fill, against its true disparity.
#include "reconstruct/left_view_edge.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "calib/core/input_error.h"
#include "reconstruct/disparity_state_testing.h"
#include "reconstruct/matcher.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

using testing::StateOf;

// Columns >= 150 without data and one pixel (60, 20) without: with a 9 x 3
// window a point is dropped iff x + 4 >= 150, or |x - 60| <= 4 and
// |y - 20| <= 1, or its window leaves the image (x < 4, x > 195, y < 1,
// y > 38). Exact: no tolerance.
TEST(LeftViewEdge, DropsExactlyThePointsWhoseWindowReachesNoData) {
  cv::Mat valid(40, 200, CV_8UC1, cv::Scalar(255));
  valid(cv::Rect(150, 0, 50, 40)).setTo(0);
  valid.at<uint8_t>(20, 60) = 0;
  cv::Mat disparity(40, 200, CV_32FC1, cv::Scalar(20.0f));
  disparity.at<float>(30, 100) = std::numeric_limits<float>::infinity();  // no point: left as it is
  DisparityState s = StateOf(disparity);
  s.status.at<uint8_t>(30, 100) = uint8_t(PixelStatus::kLowZncc);
  const cv::Rect roi(0, 0, 200, 40);
  int expected = 0;
  auto drops = [](int x, int y) {
    return x + 4 >= 150 || (std::abs(x - 60) <= 4 && std::abs(y - 20) <= 1) || x < 4 || x > 195 || y < 1 || y > 38;
  };
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 200; ++x) expected += drops(x, y) && !(x == 100 && y == 30);
  EXPECT_EQ(DropLeftViewEdge(valid, 4, 1, roi, &s), expected);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 200; ++x) {
      if (x == 100 && y == 30) {
        EXPECT_EQ(s.status.at<uint8_t>(y, x), uint8_t(PixelStatus::kLowZncc));
        continue;
      }
      const bool dropped = !std::isfinite(s.disparity_px.at<float>(y, x));
      ASSERT_EQ(dropped, drops(x, y)) << x << " " << y;
      EXPECT_EQ(s.status.at<uint8_t>(y, x), uint8_t(dropped ? PixelStatus::kLeftViewEdge : PixelStatus::kPoint));
      EXPECT_EQ(s.confidence.at<float>(y, x), dropped ? 0.0f : 0.9f);
    }
  // No mask: nothing touched.
  DisparityState untouched = StateOf(disparity);
  EXPECT_EQ(DropLeftViewEdge(cv::Mat(), 4, 1, roi, &untouched), 0);
}

struct EdgeErrors {
  int points = 0;             // valid pixels within 12 columns of the edge
  int beyond_half_px = 0;     // of those, |d - truth| > 0.5 px
  double max_abs_px = 0;      // over the whole image
  int window_in_no_data = 0;  // valid pixels whose 9 x 3 window reaches a column >= the edge
};

EdgeErrors ErrorsAtTheEdge(const MatchResult& m, const SyntheticPair& pair, int edge_x, int margin) {
  EdgeErrors e;
  for (int y = margin; y < pair.left.rows - margin; ++y)
    for (int x = margin; x < edge_x; ++x) {
      // As matcher_test.cc's Score: a true match outside the right image measures nothing.
      if (x - pair.true_disparity_px.at<double>(y, x) < margin) continue;
      const float d = m.disparity_px.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const double err = std::abs(d - pair.true_disparity_px.at<double>(y, x));
      e.max_abs_px = std::max(e.max_abs_px, err);
      if (x >= edge_x - 12) {
        ++e.points;
        e.beyond_half_px += err > 0.5;
      }
      e.window_in_no_data += x + 4 >= edge_x;
    }
  return e;
}

// A slanted plane (d = 40 + 0.04 x + 0.015 y, the matcher tests' pair) whose
// left image has no data from column 260 on, as a rectified left view past
// its sensor's edge: zero there. Without the test the windows that hold the
// step to zero put points off by more than half a pixel along the edge (the
// control: the step is the strongest feature such a window holds); with it,
// no point is more than 0.5 px off anywhere, the whole-plane bound of
// matcher_test.cc's SlantedLaserGridPlaneIsAccurateAndNotPeakLocked, and
// the points 5-12 columns from the edge are kept.
TEST(LeftViewEdge, TheMatcherKeepsNoPointWhoseWindowHoldsTheZeroFill) {
  SyntheticPairSpec spec;
  SyntheticPair pair = RenderSyntheticPair(spec);
  const int edge_x = 260;
  pair.left(cv::Rect(edge_x, 0, spec.width - edge_x, spec.height)).setTo(0);
  cv::Mat left_valid(pair.left.size(), CV_8UC1, cv::Scalar(255));
  left_valid(cv::Rect(edge_x, 0, spec.width - edge_x, spec.height)).setTo(0);
  MatchOptions o;
  o.min_disparity_px = 24;
  o.num_disparities = 64;
  const int margin = 12;  // the image border: windows undefined there (matcher_test.cc)
  const EdgeErrors without = ErrorsAtTheEdge(Match(pair.left, pair.right, o), pair, edge_x, margin);
  o.left_valid = left_valid;
  const MatchResult with_test = Match(pair.left, pair.right, o);
  const EdgeErrors with = ErrorsAtTheEdge(with_test, pair, edge_x, margin);
  std::printf("without the test: %d points by the edge, %d off by > 0.5 px, max %.2f px; with: %d, %d, max %.2f px\n",
              without.points, without.beyond_half_px, without.max_abs_px, with.points, with.beyond_half_px,
              with.max_abs_px);
  EXPECT_GT(without.beyond_half_px, 0);  // the control
  EXPECT_GT(without.window_in_no_data, 0);
  EXPECT_EQ(with.window_in_no_data, 0);
  EXPECT_EQ(with.beyond_half_px, 0);
  EXPECT_LT(with.max_abs_px, 0.5);
  // Columns edge - 12 .. edge - 5 over the rows scored: what is left by the
  // edge, nearly all of it (the plane is smooth and fully lit).
  EXPECT_GT(with.points, 0.9 * 8 * (spec.height - 2 * margin));
  int status_count = 0;
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x)
      status_count += with_test.status.at<uint8_t>(y, x) == uint8_t(PixelStatus::kLeftViewEdge);
  EXPECT_GT(status_count, 0);
}

TEST(LeftViewEdge, AMaskOfAnotherSizeIsBadInput) {
  SyntheticPairSpec spec;
  spec.width = 64, spec.height = 48;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  MatchOptions o;
  o.min_disparity_px = 24;
  o.num_disparities = 16;
  o.left_valid = cv::Mat(10, 10, CV_8UC1, cv::Scalar(255));
  EXPECT_THROW(Match(pair.left, pair.right, o), InputError);
  o.left_valid = cv::Mat(pair.left.size(), CV_32FC1, cv::Scalar(1));
  EXPECT_THROW(Match(pair.left, pair.right, o), InputError);
}

}  // namespace
}  // namespace stereorig
