// The lit mask against its definition written with OpenCV's box filter (the
// runtime's code before the one-pass kernel): the same bits on random
// images, at the edges (the reflected window) and on images smaller than
// the window.
#include "reconstruct/lit_mask.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

namespace stereorig {
namespace {

cv::Mat BoxFilterLitMask(const cv::Mat& grey, double contrast_dn) {
  cv::Mat f, mean, mean2;
  grey.convertTo(f, CV_32F);
  cv::boxFilter(f, mean, CV_32F, cv::Size(9, 9));
  cv::boxFilter(f.mul(f), mean2, CV_32F, cv::Size(9, 9));
  cv::Mat var = mean2 - mean.mul(mean);
  return var > float(contrast_dn * contrast_dn);
}

// Exact: both sides round the same integer sums the same way, so no
// tolerance; every size must agree on every pixel.
TEST(LitMask, SameBitsAsTheBoxFilterDefinition) {
  std::mt19937 rng(5);
  for (const cv::Size size : {cv::Size(97, 61), cv::Size(9, 9), cv::Size(5, 3), cv::Size(1, 12), cv::Size(30, 1)}) {
    cv::Mat parent(size.height + 6, size.width + 10, CV_8UC1);
    cv::randu(parent, 0, 256);
    // A dark half and smooth ramps: lit and unlit pixels side by side.
    for (int y = 0; y < parent.rows; ++y)
      for (int x = 0; x < parent.cols / 2; ++x) parent.at<uint8_t>(y, x) = uint8_t((x + y + rng() % 3) % 256);
    const cv::Mat grey = parent(cv::Rect(4, 3, size.width, size.height));  // a view: its parent's pixels are not read
    for (const double contrast : {0.0, 1.0, 12.0, 40.0, 73.5}) {
      const cv::Mat expected = BoxFilterLitMask(grey, contrast);
      const cv::Mat got = LitMask(grey, contrast);
      ASSERT_EQ(got.type(), CV_8UC1);
      ASSERT_EQ(got.size(), size);
      EXPECT_EQ(cv::countNonZero(got != expected), 0) << size << " contrast " << contrast;
    }
  }
}

// A grid-lit square on a dark background: lit inside, not far outside.
TEST(LitMask, LitWhereTheGridIsAndNotOnUniformDark) {
  cv::Mat grey(60, 80, CV_8UC1, cv::Scalar(10));
  for (int y = 20; y < 40; ++y)
    for (int x = 20; x < 60; ++x) grey.at<uint8_t>(y, x) = (x % 4 < 2) ? 200 : 20;
  const cv::Mat lit = LitMask(grey, 12.0);
  EXPECT_EQ(lit.at<uint8_t>(30, 40), 255);
  EXPECT_EQ(lit.at<uint8_t>(5, 5), 0);
  EXPECT_EQ(lit.at<uint8_t>(55, 75), 0);
}

// A view whose right part is the remap's zero fill (no sensor data): a
// window reaching it is not on data, one 5 px away (beyond the 9x9
// window's half of 4) is; the image's own edges count as data (LitMask
// reflects there, no step). And on a flat grey view, where LitMask's only
// contrast is that step, nothing is left lit once masked.
TEST(LitWindowOnData, ExcludesWindowsOverTheZeroFillOnly) {
  cv::Mat valid(40, 60, CV_8UC1, cv::Scalar(255));
  valid(cv::Rect(50, 0, 10, 40)).setTo(0);  // columns 50..59: no data
  const cv::Mat on_data = LitWindowOnData(valid);
  ASSERT_EQ(on_data.size(), valid.size());
  for (int y : {0, 20, 39}) {
    EXPECT_EQ(on_data.at<uint8_t>(y, 45), 255) << y;  // window columns 41..49
    EXPECT_EQ(on_data.at<uint8_t>(y, 46), 0) << y;    // reaches column 50
    EXPECT_EQ(on_data.at<uint8_t>(y, 55), 0) << y;
    EXPECT_EQ(on_data.at<uint8_t>(y, 0), 255) << y;  // the image's edge is no step
  }
  cv::Mat flat(40, 60, CV_8UC1, cv::Scalar(128));
  flat.setTo(0, valid == 0);
  const cv::Mat lit = LitMask(flat, 5.0);
  EXPECT_GT(cv::countNonZero(lit), 0);  // the step alone reads as lit
  cv::Mat masked;
  cv::bitwise_and(lit, on_data, masked);
  EXPECT_EQ(cv::countNonZero(masked), 0);
}

}  // namespace
}  // namespace stereorig
