// The union-find speckle filter against OpenCV's cv::filterSpeckles (the
// flood fill the matcher used before it): the same pixels removed, bit for
// bit, on random blob maps; and an analytic case.
#include "reconstruct/speckle_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <random>
#include <tuple>

namespace stereorig {
namespace {

constexpr int16_t kInvalid = -32768;

// Patches of random constant level plus small noise, some pixels invalid:
// blobs of every size, joined and split by the noise at the max_diff edge.
cv::Mat RandomBlobMap(std::mt19937& rng, cv::Size size, int invalid_percent) {
  cv::Mat coarse(size.height / 4 + 1, size.width / 4 + 1, CV_16SC1);
  std::uniform_int_distribution<int> level(-400, 400), noise(-12, 12), percent(0, 99);
  for (int y = 0; y < coarse.rows; ++y)
    for (int x = 0; x < coarse.cols; ++x) coarse.at<int16_t>(y, x) = int16_t(level(rng));
  cv::Mat map(size, CV_16SC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      map.at<int16_t>(y, x) = percent(rng) < invalid_percent
                                  ? kInvalid
                                  : int16_t(coarse.at<int16_t>(y / 4, x / 4) + (percent(rng) < 30 ? noise(rng) : 0));
  return map;
}

// Exact: both label the same blobs, so no tolerance.
TEST(FilterSpeckles16, RemovesTheSamePixelsAsOpenCv) {
  std::mt19937 rng(11);
  int removed_total = 0;
  for (const cv::Size size : {cv::Size(123, 77), cv::Size(1, 40), cv::Size(40, 1), cv::Size(8, 8)})
    for (const int invalid_percent : {0, 10, 40})
      for (const int max_diff : {0, 8, 16, 30})
        for (const int max_blob : {0, 1, 7, 50, 100}) {
          cv::Mat parent = RandomBlobMap(rng, cv::Size(size.width + 6, size.height + 4), invalid_percent);
          const cv::Rect inner(3, 2, size.width, size.height);
          cv::Mat expected = parent(inner).clone();
          cv::filterSpeckles(expected, kInvalid, max_blob, max_diff);
          const cv::Mat before = parent.clone();
          FilterSpeckles16(parent(inner), kInvalid, max_blob, max_diff);  // a view: its parent's pixels stay
          const cv::Mat got = parent(inner);
          ASSERT_EQ(cv::countNonZero(got != expected), 0)
              << size << " invalid " << invalid_percent << "% diff " << max_diff << " blob " << max_blob;
          cv::Mat outside_changed = parent != before;
          outside_changed(inner).setTo(0);
          ASSERT_EQ(cv::countNonZero(outside_changed), 0);
          removed_total += cv::countNonZero((got == kInvalid) & (before(inner) != kInvalid));
        }
  EXPECT_GT(removed_total, 1000);  // the maps did have blobs to remove
}

// A 3x3 square of 9 px on an invalid background, next to a 4x5 one of 20 px
// one step (17 > max_diff 16) away: only blobs of <= max_blob px go, and
// the step keeps the two apart.
TEST(FilterSpeckles16, RemovesBlobsUpToTheSize) {
  cv::Mat map(10, 12, CV_16SC1, cv::Scalar(kInvalid));
  map(cv::Rect(1, 1, 3, 3)).setTo(100);
  map(cv::Rect(4, 1, 4, 5)).setTo(117);
  for (const auto& [max_blob, small_kept, large_kept] : {std::tuple{8, true, true}, std::tuple{9, false, true},
                                                         std::tuple{19, false, true}, std::tuple{20, false, false}}) {
    cv::Mat m = map.clone();
    FilterSpeckles16(m, kInvalid, max_blob, 16);
    EXPECT_EQ(m.at<int16_t>(2, 2) == 100, small_kept) << max_blob;
    EXPECT_EQ(m.at<int16_t>(3, 5) == 117, large_kept) << max_blob;
  }
  cv::Mat joined = map.clone();
  FilterSpeckles16(joined, kInvalid, 20, 17);  // the step is within reach: one blob of 29 px
  EXPECT_EQ(joined.at<int16_t>(2, 2), 100);
}

// The float form against its definition: lround of the clamped value in
// 1/16 px, OpenCV's filter, +inf where invalid. Random values cover both
// signs, -0, halves (x.5 / 16 rounds away from zero), values beyond the
// +-2000 px clamp, NaN and +-inf; widths not a multiple of the 8-lane
// kernel. Exact, no tolerance.
TEST(RemoveSpeckleBlobs, MatchesRoundingThenOpenCvFilter) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> percent(0, 99);
  std::uniform_real_distribution<float> level(-30, 30), jitter(-0.08f, 0.08f);
  const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            -0.0f,
                            0.0f,
                            2500.0f,
                            -2500.0f,
                            1.0f / 32,
                            -1.0f / 32,
                            3.0f / 32,
                            -5.0f / 32};
  int kept = 0, removed = 0;
  for (const cv::Size size : {cv::Size(101, 37), cv::Size(7, 5), cv::Size(16, 9)})
    for (const int max_blob : {3, 20}) {
      cv::Mat map(size, CV_32FC1);
      for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
          const float base = level(rng) * float(((x / 5 + y / 4) % 3) != 0);  // patches, some exactly 0
          const int p = percent(rng);
          map.at<float>(y, x) = p < 10 ? specials[p % std::size(specials)] : base + (p < 40 ? jitter(rng) : 0.0f);
        }
      cv::Mat fixed(size, CV_16SC1), expected = map.clone();
      for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
          const float d = map.at<float>(y, x);
          fixed.at<int16_t>(y, x) =
              std::isfinite(d) ? int16_t(std::lround(std::clamp(d * 16.0, -32000.0, 32000.0))) : kInvalid;
        }
      cv::filterSpeckles(fixed, kInvalid, max_blob, 16);
      expected.setTo(std::numeric_limits<float>::infinity(), fixed == kInvalid);
      cv::Mat got = map.clone();
      RemoveSpeckleBlobs(got, max_blob, 1.0);                                           // 16 sixteenths
      ASSERT_EQ(cv::countNonZero(got != expected), 0) << size << " blob " << max_blob;  // NaN != NaN: none left
      kept += cv::countNonZero(got == map);  // finite values kept are untouched (NaN != NaN)
      removed += cv::countNonZero((got != map) & (map == map));
    }
  EXPECT_GT(kept, 500);  // the maps had blobs on both sides of the size
  EXPECT_GT(removed, 500);
}

// Where the rounding decides whether two pixels touch (max_diff 16 = 1 px,
// blobs of 1 px removed): 0 and +-16.5/16 px round to 0 and +-17 (half away
// from zero), 17 > 16 apart, so both go; rounding half to even or up would
// join them. Past the +-2000 px clamp, 2001 and 2500 px are one blob.
// Pairs sit at the 8-lane kernel's first lanes, mid-vector and in the
// scalar tail.
TEST(RemoveSpeckleBlobs, RoundsHalvesAwayFromZeroAndClamps) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const auto& [a, b, joined] :
       {std::tuple{0.0f, 16.5f / 16, false}, std::tuple{0.0f, -16.5f / 16, false}, std::tuple{0.0f, 15.5f / 16, true},
        std::tuple{0.0f, -15.5f / 16, true}, std::tuple{2001.0f, 2500.0f, true}, std::tuple{-2500.0f, -2001.0f, true}})
    for (const int x : {0, 9, 17}) {
      cv::Mat row(1, 20, CV_32FC1, cv::Scalar(nan));
      row.at<float>(0, x) = a;
      row.at<float>(0, x + 1) = b;
      RemoveSpeckleBlobs(row, 1, 1.0);  // 16 sixteenths
      EXPECT_EQ(std::isfinite(row.at<float>(0, x)), joined) << a << " " << b << " at " << x;
      EXPECT_EQ(std::isfinite(row.at<float>(0, x + 1)), joined) << a << " " << b << " at " << x;
    }
}

// A surface steeper than the reach: dd/dx = -1.6 px/px (the ring's oblique
// plate), 40 x 30 px with 0.1 px of noise. The plain test (reach 1 px) never
// joins two row neighbours there, so every column is a blob of 30 px and a
// window of 100 removes it all; along the slopes it is one blob, and a
// 5 x 5 patch on it a grid period (8 px) off, with the same slopes, is
// still its own blob and goes.
TEST(RemoveSpeckleBlobsAlongSlopes, KeepsASurfaceSteeperThanTheReach) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(-0.1f, 0.1f);
  cv::Mat map(30, 40, CV_32FC1), slope_x(map.size(), CV_32FC1, cv::Scalar(-1.6)),
      slope_y(map.size(), CV_32FC1, cv::Scalar(0.02));
  for (int y = 0; y < map.rows; ++y)
    for (int x = 0; x < map.cols; ++x) map.at<float>(y, x) = 100 - 1.6f * x + 0.02f * y + noise(rng);
  map(cv::Rect(20, 10, 5, 5)) += 8;
  cv::Mat plain = map.clone(), along = map.clone();
  RemoveSpeckleBlobs(plain, 100, 1.0);
  RemoveSpeckleBlobsAlongSlopes(along, slope_x, slope_y, 100, 1.0);
  EXPECT_EQ(cv::countNonZero(plain == map), 0) << "the plain test cuts the surface into strips";
  const cv::Mat kept = along == map;
  EXPECT_EQ(cv::countNonZero(kept), int(map.total()) - 25);
  EXPECT_EQ(cv::countNonZero(kept(cv::Rect(20, 10, 5, 5))), 0) << "the patch a period off";
}

// The same surface turned a quarter: dd/dy = -1.6 px/px down the columns
// (the steps between a pixel and the one above it), dd/dx = 0.02. The plain
// test joins each row and no two rows: 30 px blobs, all removed; along the
// slopes one blob, and the patch a period off goes.
TEST(RemoveSpeckleBlobsAlongSlopes, KeepsASurfaceSteeperThanTheReachDownTheColumns) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> noise(-0.1f, 0.1f);
  cv::Mat map(40, 30, CV_32FC1), slope_x(map.size(), CV_32FC1, cv::Scalar(0.02)),
      slope_y(map.size(), CV_32FC1, cv::Scalar(-1.6));
  for (int y = 0; y < map.rows; ++y)
    for (int x = 0; x < map.cols; ++x) map.at<float>(y, x) = 100 + 0.02f * x - 1.6f * y + noise(rng);
  map(cv::Rect(10, 20, 5, 5)) += 8;
  cv::Mat plain = map.clone(), along = map.clone();
  RemoveSpeckleBlobs(plain, 100, 1.0);
  RemoveSpeckleBlobsAlongSlopes(along, slope_x, slope_y, 100, 1.0);
  EXPECT_EQ(cv::countNonZero(plain == map), 0) << "the plain test cuts the surface into rows";
  const cv::Mat kept = along == map;
  EXPECT_EQ(cv::countNonZero(kept), int(map.total()) - 25);
  EXPECT_EQ(cv::countNonZero(kept(cv::Rect(10, 20, 5, 5))), 0) << "the patch a period off";
}

// Where every predicted step is within the reach (|slopes| < 0.5 px/px,
// their sum's step < 1 px), the filter is RemoveSpeckleBlobs, bit for bit,
// on random blob maps.
TEST(RemoveSpeckleBlobsAlongSlopes, IsThePlainFilterWhereTheSlopesAreWithinTheReach) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> level(-30, 30), jitter(-0.6f, 0.6f), slope(-0.49f, 0.49f);
  std::uniform_int_distribution<int> percent(0, 99);
  int removed = 0;
  for (const cv::Size size : {cv::Size(101, 37), cv::Size(16, 9)}) {
    cv::Mat map(size, CV_32FC1), slope_x(size, CV_32FC1), slope_y(size, CV_32FC1);
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        const int p = percent(rng);
        map.at<float>(y, x) = p < 10 ? std::numeric_limits<float>::infinity()
                                     : level(rng) * float((x / 5 + y / 4) % 3 != 0) + jitter(rng);
        slope_x.at<float>(y, x) = slope(rng);
        slope_y.at<float>(y, x) = slope(rng);
      }
    cv::Mat plain = map.clone(), along = map.clone();
    RemoveSpeckleBlobs(plain, 20, 1.0);
    RemoveSpeckleBlobsAlongSlopes(along, slope_x, slope_y, 20, 1.0);
    ASSERT_EQ(cv::countNonZero(plain != along), 0) << size;
    removed += cv::countNonZero(plain != map);
  }
  EXPECT_GT(removed, 100);
}

}  // namespace
}  // namespace stereorig
