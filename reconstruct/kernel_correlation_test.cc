// The correlations of kernel_correlation.h against cv::filter2D, which they
// replaced in the surface fit: the same floats, element for element, so no
// tolerance. On random rows with many zeros (as the fit's masked moments
// have), row widths that leave 0-7 columns past the last 8-wide block, and
// the fit's kernels: (x / half)^p for p = 0..4 (odd p: a zero centre tap,
// which filter2D skips). What the check can catch: the taps taken in
// reverse order (planted when writing it) fail every width, half and power
// of the first two tests, with mismatches in about half the outputs; each
// product rounded apart (multiply, then add: filter2D's arithmetic without
// FMA) differed in 35-45 % of such outputs in a standalone comparison.
#include "reconstruct/kernel_correlation.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>
#include <vector>

namespace stereorig {
namespace {

// The surface fit's taps (local_surface_fit.cc, PowerTaps).
std::vector<float> PowerTaps(int half, int power) {
  std::vector<float> k;
  for (int x = -half; x <= half; ++x) k.push_back(float(std::pow(double(x) / half, power)));
  return k;
}

cv::Mat RandomImage(int rows, int cols, std::mt19937* rng) {
  std::uniform_real_distribution<float> value(-3.f, 3.f), unit(0.f, 1.f);
  cv::Mat m(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) m.at<float>(y, x) = unit(*rng) < 0.4f ? 0.f : value(*rng);
  return m;
}

// filter2D's vectorised sums use FMA only where the CPU has it; elsewhere
// it rounds each product, and these functions (always fused) differ.
bool OpenCvFuses() { return cv::checkHardwareSupport(CV_CPU_FMA3) && cv::checkHardwareSupport(CV_CPU_AVX2); }

TEST(KernelCorrelation, AlongARowEqualsFilter2D) {
  if (!OpenCvFuses()) GTEST_SKIP() << "filter2D rounds products apart on this CPU";
  std::mt19937 rng(5);
  for (const int width : {37, 47, 64, 100, 428, 753}) {
    const cv::Mat image = RandomImage(12, width, &rng);
    for (const int half : {10, 5, 2}) {
      for (int power = 0; power <= 4; ++power) {
        SCOPED_TRACE(testing::Message() << "width " << width << " half " << half << " power " << power);
        const std::vector<float> taps = PowerTaps(half, power);
        cv::Mat expected;
        cv::filter2D(image, expected, CV_32F, cv::Mat(1, int(taps.size()), CV_32F, const_cast<float*>(taps.data())),
                     cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
        const KernelTaps k = NonzeroTaps(taps.data(), half);
        std::vector<float> out(size_t(width) + 1, -7.f);  // one sentinel past the row
        int mismatches = 0;
        for (int y = 0; y < image.rows; ++y) {
          CorrelateAlongRow(image.ptr<float>(y), width, k, out.data());
          for (int x = 0; x < width; ++x) mismatches += out[size_t(x)] != expected.at<float>(y, x);
        }
        EXPECT_EQ(mismatches, 0);
        EXPECT_EQ(out[size_t(width)], -7.f);  // nothing written past the row
      }
    }
  }
}

// As the surface fit uses it: filter2D of a band of rows' view reads the
// rows around the band from the whole stack (0 only beyond its ends).
TEST(KernelCorrelation, DownColumnsEqualsFilter2DOnAViewOfTheRows) {
  if (!OpenCvFuses()) GTEST_SKIP() << "filter2D rounds products apart on this CPU";
  std::mt19937 rng(6);
  for (const int width : {37, 428}) {
    const cv::Mat stack = RandomImage(40, width, &rng);
    for (const int half : {5, 10}) {
      for (int power = 0; power <= 4; ++power) {
        SCOPED_TRACE(testing::Message() << "width " << width << " half " << half << " power " << power);
        const std::vector<float> taps = PowerTaps(half, power);
        const cv::Mat kernel(int(taps.size()), 1, CV_32F, const_cast<float*>(taps.data()));
        const KernelTaps k = NonzeroTaps(taps.data(), half);
        std::vector<float> out(static_cast<size_t>(width));
        int mismatches = 0;
        // Rows 3..30: their windows reach past the stack's first rows (0
        // there) and into rows outside the view (read as they are).
        const cv::Range rows(3, 30);
        cv::Mat expected;
        cv::filter2D(stack.rowRange(rows), expected, CV_32F, kernel, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
        for (int y = rows.start; y < rows.end; ++y) {
          CorrelateDownColumns(stack.ptr<float>(0), long(stack.step1()), stack.rows, y, width, k, out.data());
          for (int x = 0; x < width; ++x) mismatches += out[size_t(x)] != expected.at<float>(y - rows.start, x);
        }
        EXPECT_EQ(mismatches, 0);
      }
    }
  }
}

TEST(KernelCorrelation, NonzeroTapsKeepsOrderAndOffsets) {
  const float taps[5] = {1.f, 0.f, 2.f, 0.f, -3.f};
  const KernelTaps k = NonzeroTaps(taps, 2);
  EXPECT_EQ(k.value, (std::vector<float>{1.f, 2.f, -3.f}));
  EXPECT_EQ(k.offset, (std::vector<int>{-2, 0, 2}));
}

}  // namespace
}  // namespace stereorig
