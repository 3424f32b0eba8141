// The grid-line support test: ridges on constructed profiles and the drop
// on a constructed image (exact), and the matcher on an analytically
// rendered grid-lit plane, which the test must leave whole.
#include "reconstruct/grid_line_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "calib/core/input_error.h"
#include "reconstruct/disparity_state_testing.h"
#include "reconstruct/matcher.h"
#include "reconstruct/runtime_options.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

using testing::StateOf;

// One row profile, repeated on every row (so no column is a ridge):
// background 20 DN;
//   x = 2: a line too near the image's edge to be tested (reach 4): none;
//   x = 10: a laser line, 60 DN over troughs of 20: a ridge;
//   x = 30: an outline's step 20 -> 120 with a 5 DN overshoot at x = 31:
//     on one side only, and the overshoot stands 5 < 8 DN above the
//     plateau: none;
//   x = 45: a bump 6 DN high: none;
//   x = 52: a bump exactly 8 DN high (the threshold, inclusive): a ridge.
cv::Mat Profiles(int rows) {
  cv::Mat grey(rows, 60, CV_8UC1, cv::Scalar(20));
  for (int y = 0; y < rows; ++y) {
    uint8_t* g = grey.ptr<uint8_t>(y);
    g[1] = 40, g[2] = 70, g[3] = 40;
    g[9] = 40, g[10] = 80, g[11] = 40;
    for (int x = 30; x < 40; ++x) g[x] = 120;
    g[29] = 60, g[31] = 125;
    g[45] = 26;
    g[52] = 28;
  }
  return grey;
}

TEST(GridLine, RidgesAreLinePeaksNotStepsOrShallowBumps) {
  const cv::Mat grey = Profiles(20);
  const cv::Mat ridges = GridRidges(grey, 4, 8.0);
  ASSERT_EQ(ridges.size(), grey.size());
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x)
      EXPECT_EQ(ridges.at<uint8_t>(y, x), (x == 10 || x == 52) ? 1 : 0) << x << " " << y;
  // The same along the columns.
  cv::Mat grey_t, ridges_t;
  cv::transpose(grey, grey_t);
  cv::transpose(GridRidges(grey_t, 4, 8.0), ridges_t);
  EXPECT_EQ(cv::norm(ridges_t != ridges, cv::NORM_L1), 0.0);
  // A higher threshold loses the 8 DN bump, keeps the line.
  const cv::Mat strict = GridRidges(grey, 4, 9.0);
  EXPECT_EQ(cv::countNonZero(strict.col(52)), 0);
  EXPECT_EQ(cv::countNonZero(strict.col(10)), grey.rows);
}

// Lines (ridges along the rows) at x = 6 and x = 20, 28, ..., 92 on a
// 30 DN background; from x = 100 an ambient-lit plateau (120 DN) that ends
// at x = 150 in an outline against a 16 DN background. A point everywhere
// at d = 10; the ROI starts at x = 10, so the line at x = 6 lies outside it
// but within reach of its windows. Radius 5, 3 ridge pixels: a point is kept
// exactly when a line lies within 5 columns (the window then holds >= 6 of
// its pixels), so x = 10, 11 (the line at 6) and 15..97 are kept, 12..14 and
// >= 98 (the plateau, the outline, the background) dropped. Outside the
// ROI nothing changes; a pixel without a point keeps its status.
TEST(GridLine, DropsExactlyThePointsNoLineSupports) {
  cv::Mat grey(60, 200, CV_8UC1, cv::Scalar(30));
  std::set<int> lines = {6};
  for (int x = 20; x <= 92; x += 8) lines.insert(x);
  for (int x : lines) grey.col(x).setTo(90), grey.col(x - 1).setTo(60), grey.col(x + 1).setTo(60);
  grey(cv::Rect(100, 0, 50, 60)).setTo(120);
  grey(cv::Rect(150, 0, 50, 60)).setTo(16);
  DisparityState s = StateOf(cv::Mat(60, 200, CV_32FC1, cv::Scalar(10.0f)));
  s.disparity_px.at<float>(30, 120) = std::numeric_limits<float>::infinity();
  s.status.at<uint8_t>(30, 120) = uint8_t(PixelStatus::kLowZncc);
  const cv::Rect roi(10, 5, 180, 50);
  GridLineOptions o;
  ASSERT_EQ(o.radius_px, 5);
  ASSERT_EQ(o.min_ridge_px, 3);
  int expected = 0;
  auto kept = [&](int x) {
    for (int c : lines)
      if (std::abs(x - c) <= 5) return true;
    return false;
  };
  for (int y = roi.y; y < roi.br().y; ++y)
    for (int x = roi.x; x < roi.br().x; ++x) expected += !kept(x) && !(x == 120 && y == 30);
  EXPECT_EQ(DropWithoutGridLine(grey, o, 4, roi, &s), expected);
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 200; ++x) {
      const bool dropped = roi.contains(cv::Point(x, y)) && !kept(x) && !(x == 120 && y == 30);
      ASSERT_EQ(std::isfinite(s.disparity_px.at<float>(y, x)), !dropped && !(x == 120 && y == 30)) << x << " " << y;
      const PixelStatus want = (x == 120 && y == 30) ? PixelStatus::kLowZncc
                               : dropped             ? PixelStatus::kNoGridLine
                                                     : PixelStatus::kPoint;
      EXPECT_EQ(s.status.at<uint8_t>(y, x), uint8_t(want)) << x << " " << y;
      EXPECT_EQ(s.confidence.at<float>(y, x), dropped ? 0.0f : 0.9f);
    }
  // Off: nothing is touched.
  DisparityState untouched = StateOf(cv::Mat(60, 200, CV_32FC1, cv::Scalar(10.0f)));
  o.enabled = false;
  EXPECT_EQ(DropWithoutGridLine(grey, o, 4, roi, &untouched), 0);
  EXPECT_EQ(cv::countNonZero(untouched.status != uint8_t(PixelStatus::kPoint)), 0);
}

// The matcher tests' slanted plane under the grid (d = 40 + 0.04 x +
// 0.015 y, grid period 8 px, lines 150 DN, noise 2 DN): every pixel of it
// lies within half a period of a line, so the test must drop no point and
// change none (the same map to the float with the test off).
TEST(GridLine, TheMatcherKeepsAGridLitPlaneWhole) {
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  MatchOptions o;
  o.min_disparity_px = 24;
  o.num_disparities = 64;
  o.grid_line.enabled = false;
  const MatchResult without_test = Match(pair.left, pair.right, o);
  o.grid_line.enabled = true;
  const MatchResult with_test = Match(pair.left, pair.right, o);
  EXPECT_GT(cv::countNonZero(with_test.status == uint8_t(PixelStatus::kPoint)), 50000);
  EXPECT_EQ(cv::countNonZero(with_test.status == uint8_t(PixelStatus::kNoGridLine)), 0);
  EXPECT_EQ(cv::norm(with_test.status != without_test.status, cv::NORM_L1), 0.0);
  const cv::Mat a = with_test.disparity_px, b = without_test.disparity_px;
  EXPECT_EQ(cv::countNonZero((a != b) & (a == a)), 0);  // NaN-free maps: +inf marks no point
}

// The rule written out pixel by pixel, as the header states it: along a row
// (a column), a pixel at least k from the image's edge that is >= the pixel
// before it and > the one after it and stands >= ceil(c) above the lowest of
// the k before it and of the k after it.
cv::Mat ReferenceRidges(const cv::Mat& grey, int k, double c) {
  cv::Mat out(grey.size(), CV_8UC1, cv::Scalar(0));
  const int height = int(std::ceil(c));
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x) {
      const int v = grey.at<uint8_t>(y, x);
      for (const bool along_x : {true, false}) {
        const int n = along_x ? grey.cols : grey.rows, i = along_x ? x : y;
        if (i < k || i >= n - k) continue;
        auto at = [&](int j) { return int(along_x ? grey.at<uint8_t>(y, j) : grey.at<uint8_t>(j, x)); };
        int low_before = 255, low_after = 255;
        for (int s = 1; s <= k; ++s)
          low_before = std::min(low_before, at(i - s)), low_after = std::min(low_after, at(i + s));
        if (v >= at(i - 1) && v > at(i + 1) && v - low_before >= height && v - low_after >= height)
          out.at<uint8_t>(y, x) = 1;
      }
    }
  return out;
}

// Random images of every size from 1 px, grey levels drawn from a few values
// (ties and flat tops) or the whole range, views into a larger image, reach
// 1-6, heights 0.5-60 DN: the ridges equal the reference's, and the drop
// equals the reference's count of ridges (read around the ROI as the header
// says) in each point's window. Exact.
TEST(GridLine, RidgesAndTheDropEqualAPixelByPixelReference) {
  cv::RNG rng(25);
  for (int trial = 0; trial < 300; ++trial) {
    const int rows = rng.uniform(1, 41), cols = rng.uniform(1, 41);
    cv::Mat big(rows + 6, cols + 6, CV_8UC1);
    if (trial % 2 == 0) {
      rng.fill(big, cv::RNG::UNIFORM, 0, 256);
    } else {  // few levels: ties everywhere
      for (int y = 0; y < big.rows; ++y)
        for (int x = 0; x < big.cols; ++x) big.at<uint8_t>(y, x) = uint8_t(20 * rng.uniform(0, 4));
    }
    const cv::Mat grey = big(cv::Rect(3, 3, cols, rows));  // a view
    const int k = rng.uniform(1, 7);
    const double c = rng.uniform(0.5, 60.0);
    const cv::Mat ridges = GridRidges(grey, k, c), reference = ReferenceRidges(grey, k, c);
    ASSERT_EQ(cv::norm(ridges != reference, cv::NORM_L1), 0.0) << "trial " << trial << " k " << k << " c " << c;

    GridLineOptions o;
    o.min_prominence_dn = c;
    o.radius_px = rng.uniform(1, 8);
    o.min_ridge_px = rng.uniform(1, 6);
    const cv::Rect roi(rng.uniform(0, cols), rng.uniform(0, rows), 0, 0);
    const cv::Rect box = cv::Rect(roi.x, roi.y, rng.uniform(1, cols - roi.x + 1), rng.uniform(1, rows - roi.y + 1));
    cv::Mat disparity(rows, cols, CV_32FC1, cv::Scalar(10.0f));
    for (int i = 0; i < rows * cols / 5; ++i)
      disparity.at<float>(rng.uniform(0, rows), rng.uniform(0, cols)) = std::numeric_limits<float>::infinity();
    DisparityState s = StateOf(disparity);
    const int dropped = DropWithoutGridLine(grey, o, k, box, &s);
    // The reference: ridges of the area the windows and their ridge tests
    // reach, counted in each window.
    const int r = o.radius_px;
    const cv::Rect image(0, 0, cols, rows);
    const cv::Rect windows = cv::Rect(box.x - r, box.y - r, box.width + 2 * r, box.height + 2 * r) & image;
    const cv::Rect read = cv::Rect(windows.x - k, windows.y - k, windows.width + 2 * k, windows.height + 2 * k) & image;
    const cv::Mat read_ridges = ReferenceRidges(grey(read), k, c);
    int expected = 0;
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < cols; ++x) {
        int count = 0;
        for (int v = y - r; v <= y + r; ++v)
          for (int u = x - r; u <= x + r; ++u)
            if (read.contains(cv::Point(u, v))) count += read_ridges.at<uint8_t>(v - read.y, u - read.x);
        const bool valid = std::isfinite(disparity.at<float>(y, x));
        const bool drop = valid && box.contains(cv::Point(x, y)) && count < o.min_ridge_px;
        expected += drop;
        ASSERT_EQ(std::isfinite(s.disparity_px.at<float>(y, x)), valid && !drop)
            << "trial " << trial << " " << x << " " << y;
        ASSERT_EQ(s.status.at<uint8_t>(y, x), uint8_t(drop ? PixelStatus::kNoGridLine : PixelStatus::kPoint));
      }
    ASSERT_EQ(dropped, expected) << "trial " << trial;
  }
}

TEST(GridLine, TheOptionsAreReadAndChecked) {
  const RuntimeOptions defaults;
  EXPECT_TRUE(defaults.match.grid_line.enabled);
  const RuntimeOptions o = ParseRuntimeOptions(
      "match:\n  grid_line_test: false\n  grid_line_min_prominence_dn: 12\n  grid_line_radius_px: 8\n"
      "  grid_line_min_ridge_px: 5\n",
      "test");
  EXPECT_FALSE(o.match.grid_line.enabled);
  EXPECT_EQ(o.match.grid_line.min_prominence_dn, 12);
  EXPECT_EQ(o.match.grid_line.radius_px, 8);
  EXPECT_EQ(o.match.grid_line.min_ridge_px, 5);
  EXPECT_THROW(ParseRuntimeOptions("match:\n  grid_line_radius_px: 0\n", "test"), InputError);
  EXPECT_THROW(ParseRuntimeOptions("match:\n  grid_line_min_prominence_dn: 0\n", "test"), InputError);
  // (2 * 2 + 1)^2 = 25 pixels in a radius-2 window: 26 cannot be met.
  EXPECT_THROW(ParseRuntimeOptions("match:\n  grid_line_radius_px: 2\n  grid_line_min_ridge_px: 26\n", "test"),
               InputError);
}

}  // namespace
}  // namespace stereorig
