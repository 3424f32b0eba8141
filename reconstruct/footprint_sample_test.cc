// The footprint sampler against a hand-worked footprint and against the
// plain listing it replaces (every footprint pixel listed, stable-sorted by
// index, duplicates dropped keeping the first listed, then strided), on
// random disparity maps whose components are labelled as the line index
// labels them.
#include "reconstruct/footprint_sample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "reconstruct/line_index.h"

namespace stereorig {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The plain listing (line_index.cc before the sampler): valid pixels in
// the component's order, then each one's gap pixels left then right.
std::vector<FootprintStart> PlainSample(const cv::Mat& d, const cv::Mat& gx, const cv::Mat& gy,
                                        const std::vector<int>& pixels, int gap_px, int samples) {
  const int cols = d.cols;
  auto at = [&](const cv::Mat& m, int i) { return m.at<float>(i / cols, i % cols); };
  std::vector<FootprintStart> all;
  for (int i : pixels)
    if (std::isfinite(at(d, i))) all.push_back({i, at(d, i), at(gx, i), at(gy, i)});
  const size_t valid = all.size();
  for (size_t k = 0; k < valid; ++k) {
    const FootprintStart s = all[k];
    const int x = s.i % cols;
    for (const int dir : {-1, 1})
      for (int u = 1; u <= gap_px; ++u) {
        const int xu = x + dir * u;
        if (xu < 0 || xu >= cols || std::isfinite(at(d, s.i + dir * u))) break;
        all.push_back({s.i + dir * u, s.d + float(dir * u) * s.slope_x, s.slope_x, s.slope_y});
      }
  }
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.i < b.i; });
  all.erase(std::unique(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.i == b.i; }), all.end());
  std::vector<FootprintStart> sample;
  const double stride = std::max(1.0, double(all.size()) / samples);
  for (double k = 0.5 * stride; k < double(all.size()); k += stride) sample.push_back(all[size_t(k)]);
  return sample;
}

// One row, worked by hand: valid pixels at x = 10, 11, 12 (disparity 20,
// slope 0.5) and at x = 16 (disparity 30, slope -1); gap 2. Footprint: x = 8
// .. 14 from the first run and 15, 17, 18 from x = 16 (x = 14 is reached
// from both, and takes x = 12, listed first).
TEST(FootprintSample, ListsValidAndGapPixelsWithTheirSourcesDisparity) {
  cv::Mat d(3, 30, CV_32FC1, cv::Scalar(kInf)), gx(3, 30, CV_32FC1, cv::Scalar(0)), gy = gx.clone();
  const int y = 1, cols = 30;
  for (int x : {10, 11, 12}) d.at<float>(y, x) = 20, gx.at<float>(y, x) = 0.5f, gy.at<float>(y, x) = 0.25f;
  d.at<float>(y, 16) = 30, gx.at<float>(y, 16) = -1, gy.at<float>(y, 16) = 0;
  // Listed x = 12 first: it, not x = 16, is x = 14's source.
  const std::vector<int> pixels = {y * cols + 12, y * cols + 11, y * cols + 10, y * cols + 16};
  FootprintSampler sampler(d, gx, gy, 2, 1000);
  const std::vector<FootprintStart> sample = sampler.Sample(pixels);
  const std::vector<FootprintStart> expected = {
      {y * cols + 8, 19.0f, 0.5f, 0.25f},  {y * cols + 9, 19.5f, 0.5f, 0.25f},  {y * cols + 10, 20.0f, 0.5f, 0.25f},
      {y * cols + 11, 20.0f, 0.5f, 0.25f}, {y * cols + 12, 20.0f, 0.5f, 0.25f}, {y * cols + 13, 20.5f, 0.5f, 0.25f},
      {y * cols + 14, 21.0f, 0.5f, 0.25f}, {y * cols + 15, 31.0f, -1.0f, 0.0f}, {y * cols + 16, 30.0f, -1.0f, 0.0f},
      {y * cols + 17, 29.0f, -1.0f, 0.0f}, {y * cols + 18, 28.0f, -1.0f, 0.0f}};
  EXPECT_EQ(sample, expected);
  // 11 footprint pixels, 4 samples: stride 2.75, ranks 1, 4, 6, 9.
  FootprintSampler four(d, gx, gy, 2, 4);
  EXPECT_EQ(four.Sample(pixels), (std::vector<FootprintStart>{expected[1], expected[4], expected[6], expected[9]}));
}

// Random maps of blobs with holes, at the image's edges too; components
// labelled as CorrectLineIndex labels them, some of their pixels emptied
// after labelling (as a move that refuses pixels leaves them). Every
// component's sample must equal the plain listing's, bit for bit.
TEST(FootprintSample, EqualsThePlainSortedListingOnRandomMaps) {
  std::mt19937 rng(5);
  int compared = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const cv::Size size(60 + trial % 7, 40 + trial % 5);
    cv::Mat d(size, CV_32FC1, cv::Scalar(kInf)), gx(size, CV_32FC1), gy(size, CV_32FC1);
    cv::randu(gx, -1, 1);
    cv::randu(gy, -1, 1);
    std::uniform_int_distribution<int> px(0, size.width - 1), py(0, size.height - 1), half(1, 9);
    std::uniform_real_distribution<float> level(10, 60), unit(0, 1);
    for (int blob = 0; blob < 12; ++blob) {
      const int cx = px(rng), cy = py(rng), hw = half(rng), hh = half(rng);
      const float base = level(rng);
      for (int y = std::max(0, cy - hh); y < std::min(size.height, cy + hh); ++y)
        for (int x = std::max(0, cx - hw); x < std::min(size.width, cx + hw); ++x)
          if (unit(rng) < 0.75f) d.at<float>(y, x) = base + 0.1f * float(x - cx);  // holes: gap pixels inside
    }
    std::vector<std::vector<int>> components;
    LabelDisparityComponents(d, cv::Rect(cv::Point(0, 0), size), 1.0, &components);
    for (auto& pixels : components)
      for (int i : pixels)
        if (unit(rng) < 0.05f) d.at<float>(i / size.width, i % size.width) = kInf;
    for (const int gap_px : {0, 3, 8})
      for (const int samples : {4, 48, 10000}) {
        FootprintSampler sampler(d, gx, gy, gap_px, samples);
        for (const auto& pixels : components) {
          const auto plain = PlainSample(d, gx, gy, pixels, gap_px, samples);
          ASSERT_EQ(sampler.Sample(pixels), plain) << "trial " << trial << " gap " << gap_px << " samples " << samples;
          ++compared;
        }
      }
  }
  EXPECT_GT(compared, 1000);  // not vacuous
}

}  // namespace
}  // namespace stereorig
