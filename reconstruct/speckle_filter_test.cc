// The union-find speckle filter against OpenCV's cv::filterSpeckles (the
// flood fill the matcher used before it): the same pixels removed, bit for
// bit, on random blob maps; and an analytic case.
#include "reconstruct/speckle_filter.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

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

}  // namespace
}  // namespace stereorig
