// The line index's component labelling and seam collection (line_index.h)
// against the plain code they replace (session 8: the labelling walks a
// framed label array instead of testing bounds and validity per neighbour;
// the seams come from one raster scan instead of a walk from every pixel),
// on random disparity maps with blobs, holes, NaNs and rois that touch the
// image's edges or not. Both must agree exactly: the labels and each
// component's pixel order (which decides footprint gap pixels' sources) and
// every seam's differences, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "reconstruct/line_index.h"

namespace stereorig {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The labelling before session 8: depth first from each unlabelled valid
// pixel in raster order, neighbours pushed left, right, up, down.
cv::Mat PlainLabels(const cv::Mat& d, const cv::Rect& roi, double max_step_px, std::vector<std::vector<int>>* out) {
  cv::Mat labels(d.size(), CV_32SC1, cv::Scalar(-1));
  out->clear();
  for (int y = roi.y; y < roi.y + roi.height; ++y)
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      if (labels.at<int>(y, x) >= 0 || !std::isfinite(d.at<float>(y, x))) continue;
      const int label = int(out->size());
      std::vector<int> listed;
      std::vector<cv::Point> stack{{x, y}};
      labels.at<int>(y, x) = label;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        listed.push_back(p.y * d.cols + p.x);
        for (const cv::Point q :
             {p + cv::Point(-1, 0), p + cv::Point(1, 0), p + cv::Point(0, -1), p + cv::Point(0, 1)}) {
          if (!roi.contains(q) || labels.at<int>(q) >= 0) continue;
          const float dn = d.at<float>(q);
          if (!std::isfinite(dn) || std::abs(dn - d.at<float>(p)) > max_step_px) continue;
          labels.at<int>(q) = label;
          stack.push_back(q);
        }
      }
      out->push_back(listed);
    }
  return labels;
}

// The seam collection before session 8: from every labelled pixel, the next
// labelled pixel along its row and its column within max_gap_px + 1.
std::map<std::pair<int, int>, std::vector<float>> PlainSeams(const cv::Mat& labels, const cv::Mat& d, const cv::Mat& gx,
                                                             const cv::Mat& gy, const cv::Rect& roi, int max_gap_px) {
  std::map<std::pair<int, int>, std::vector<float>> seams;
  for (int y = roi.y; y < roi.y + roi.height; ++y)
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      const int a = labels.at<int>(y, x);
      if (a < 0) continue;
      for (int dir = 0; dir < 2; ++dir)
        for (int step = 1; step <= max_gap_px + 1; ++step) {
          const cv::Point q = dir == 0 ? cv::Point(x + step, y) : cv::Point(x, y + step);
          if (!roi.contains(q)) break;
          const int b = labels.at<int>(q);
          if (b < 0) continue;
          if (b == a) break;
          const float slope = dir == 0 ? gx.at<float>(y, x) : gy.at<float>(y, x);
          const float diff = d.at<float>(q) - (d.at<float>(y, x) + slope * step);
          if (a < b)
            seams[{a, b}].push_back(diff);
          else
            seams[{b, a}].push_back(-diff);
          break;
        }
    }
  return seams;
}

// Blobs of smooth disparity (random levels, some a few px apart so that
// components meet along seams), 25 % holes, a few NaNs.
cv::Mat RandomMap(std::mt19937& rng, const cv::Size& size) {
  cv::Mat d(size, CV_32FC1, cv::Scalar(kInf));
  std::uniform_int_distribution<int> px(0, size.width - 1), py(0, size.height - 1), half(1, 12);
  std::uniform_real_distribution<float> level(10, 30), unit(0, 1);
  for (int blob = 0; blob < 14; ++blob) {
    const int cx = px(rng), cy = py(rng), hw = half(rng), hh = half(rng);
    const float base = level(rng), slope = 0.4f * (unit(rng) - 0.5f);
    for (int y = std::max(0, cy - hh); y < std::min(size.height, cy + hh); ++y)
      for (int x = std::max(0, cx - hw); x < std::min(size.width, cx + hw); ++x)
        if (unit(rng) < 0.75f) d.at<float>(y, x) = base + slope * float(x - cx);
  }
  for (int k = 0; k < 5; ++k) d.at<float>(py(rng), px(rng)) = std::numeric_limits<float>::quiet_NaN();
  return d;
}

TEST(ComponentLabels, LabelsAndSeamsEqualThePlainWalk) {
  std::mt19937 rng(11);
  int components_compared = 0, seams_compared = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const cv::Size size(50 + trial % 9, 35 + trial % 6);
    const cv::Mat d = RandomMap(rng, size);
    cv::Mat gx(size, CV_32FC1), gy(size, CV_32FC1);
    cv::randu(gx, -1, 1);
    cv::randu(gy, -1, 1);
    // Whole image (the frame's every side at the image's edge), then inset.
    const cv::Rect roi = trial % 2 == 0 ? cv::Rect(cv::Point(0, 0), size)
                                        : cv::Rect(trial % 5, 1 + trial % 3, size.width - 7, size.height - 4);
    for (const double step_px : {0.5, 1.0}) {
      std::vector<std::vector<int>> plain, fast;
      const cv::Mat plain_labels = PlainLabels(d, roi, step_px, &plain);
      const cv::Mat labels = LabelDisparityComponents(d, roi, step_px, &fast);
      ASSERT_EQ(cv::countNonZero(labels != plain_labels), 0) << "trial " << trial;
      ASSERT_EQ(fast, plain) << "trial " << trial;
      components_compared += int(plain.size());
      for (const int gap_px : {0, 3, 8}) {
        auto expected = PlainSeams(labels, d, gx, gy, roi, gap_px);
        auto seams = SeamDifferences(labels, d, gx, gy, roi, gap_px);
        // The join reads a seam's median and spread: its order is free.
        for (auto* m : {&expected, &seams})
          for (auto& [key, diffs] : *m) std::sort(diffs.begin(), diffs.end());
        ASSERT_EQ(seams, expected) << "trial " << trial << " gap " << gap_px;
        seams_compared += int(expected.size());
      }
    }
  }
  EXPECT_GT(components_compared, 1000);  // not vacuous
  EXPECT_GT(seams_compared, 500);
}

}  // namespace
}  // namespace stereorig
