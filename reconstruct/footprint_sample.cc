#include "reconstruct/footprint_sample.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "calib/core/input_error.h"

namespace stereorig {

FootprintSampler::FootprintSampler(const cv::Mat& disparity_px, const cv::Mat& slope_x, const cv::Mat& slope_y,
                                   int gap_px, int samples)
    : disparity_px_(disparity_px),
      slope_x_(slope_x),
      slope_y_(slope_y),
      cols_(disparity_px.cols),
      gap_px_(gap_px),
      samples_(samples) {
  STEREORIG_CHECK(disparity_px.type() == CV_32FC1 && disparity_px.isContinuous());
  STEREORIG_CHECK(slope_x.type() == CV_32FC1 && slope_x.size() == disparity_px.size());
  STEREORIG_CHECK(slope_y.type() == CV_32FC1 && slope_y.size() == disparity_px.size());
  STEREORIG_CHECK(gap_px >= 0 && samples >= 1);
}

template <typename Visit>
void FootprintSampler::VisitRow(int y, int x_begin, int x_end, Visit&& visit) const {
  const float* d = disparity_px_.ptr<float>(y);
  const int* order = order_.data() + size_t(y) * size_t(cols_);
  const int row = y * cols_;
  int x = x_begin;
  while (x <= x_end) {
    if (std::isfinite(d[x])) {
      if (order[x] > 0) visit(row + x, row + x);
      ++x;
      continue;
    }
    // A run [a, b] of empty pixels. Its valid neighbours a - 1 and b + 1
    // start its gap pixels if they belong to the component. A run that
    // begins or ends the scanned columns has none there: the scan spans the
    // component's columns widened by gap_px (or the image's edge).
    const int a = x;
    while (x <= x_end && !std::isfinite(d[x])) ++x;
    const int b = x - 1;
    const int left = a > x_begin && order[a - 1] > 0 ? a - 1 : -1;
    const int right = x <= x_end && order[x] > 0 ? x : -1;
    const int left_last = left >= 0 ? std::min(b, left + gap_px_) : a - 1;      // reached from the left
    const int right_first = right >= 0 ? std::max(a, right - gap_px_) : b + 1;  // reached from the right
    for (int u = a; u <= b; ++u) {
      if (u > left_last && u < right_first) u = right_first;
      if (u > b) break;
      const bool from_left = u <= left_last, from_right = u >= right_first;
      // Reached from both: the source listed first in the component.
      const int source =
          from_left && from_right ? (order[left] < order[right] ? left : right) : (from_left ? left : right);
      visit(row + u, row + source);
    }
  }
}

bool FootprintSampler::Mark(const std::vector<int>& pixels, int* x_begin, int* x_end, int* y_min, int* y_max) {
  if (order_.empty()) order_.assign(disparity_px_.total(), 0);
  STEREORIG_CHECK(order_.size() == disparity_px_.total() && disparity_px_.isContinuous());  // same map size
  const float* d = disparity_px_.ptr<float>(0);
  int x_min = INT_MAX, x_max = -1;
  *y_min = INT_MAX, *y_max = -1;
  for (size_t k = 0; k < pixels.size(); ++k) {
    const int i = pixels[k];
    if (!std::isfinite(d[i])) continue;
    order_[size_t(i)] = int(k) + 1;
    const int x = i % cols_, y = i / cols_;
    x_min = std::min(x_min, x), x_max = std::max(x_max, x);
    *y_min = std::min(*y_min, y), *y_max = std::max(*y_max, y);
  }
  if (x_max < 0) return false;
  *x_begin = std::max(0, x_min - gap_px_), *x_end = std::min(cols_ - 1, x_max + gap_px_);
  return true;
}

void FootprintSampler::Unmark(const std::vector<int>& pixels) {
  for (int i : pixels) order_[size_t(i)] = 0;
}

FootprintStart FootprintSampler::StartAt(int i, int source) const {
  const float* d = disparity_px_.ptr<float>(0);
  const int sy = source / cols_, sx = source % cols_;
  const float slope_x = slope_x_.ptr<float>(sy)[sx], slope_y = slope_y_.ptr<float>(sy)[sx];
  // A gap pixel's disparity: its source's, carried along the row.
  const float start_px = i == source ? d[i] : d[source] + float(i - source) * slope_x;
  return {i, start_px, slope_x, slope_y};
}

std::vector<FootprintStart> FootprintSampler::Sample(const std::vector<int>& pixels, int area_per_sample_px) {
  STEREORIG_CHECK(area_per_sample_px >= 0);
  std::vector<FootprintStart> sample;
  int x_begin, x_end, y_min, y_max;
  if (Mark(pixels, &x_begin, &x_end, &y_min, &y_max)) {
    row_count_.assign(size_t(y_max - y_min + 1), 0);
    size_t total = 0;
    for (int y = y_min; y <= y_max; ++y) {
      int n = 0;
      VisitRow(y, x_begin, x_end, [&n](int, int) { ++n; });
      row_count_[size_t(y - y_min)] = n;
      total += size_t(n);
    }
    // With area_per_sample_px, one sample per that much footprint if that
    // is more: the whole region is read, not just `samples_` of it.
    const double samples = area_per_sample_px > 0
                               ? std::max(double(samples_), std::floor(double(total) / area_per_sample_px))
                               : double(samples_);
    const double stride = std::max(1.0, double(total) / samples);
    double k = 0.5 * stride;  // the next rank to take, accumulated as in the plain listing
    size_t rank = 0;          // of the first footprint pixel of row y
    for (int y = y_min; y <= y_max && k < double(total); ++y) {
      const size_t n = size_t(row_count_[size_t(y - y_min)]);
      if (size_t(k) < rank + n) {
        size_t r = rank;
        VisitRow(y, x_begin, x_end, [&](int i, int source) {
          if (r++ != size_t(k) || !(k < double(total))) return;
          sample.push_back(StartAt(i, source));
          k += stride;
        });
      }
      rank += n;
    }
  }
  Unmark(pixels);
  return sample;
}

std::vector<FootprintStart> FootprintSampler::SampleLattice(const std::vector<int>& pixels, int pitch_px) {
  STEREORIG_CHECK(pitch_px >= 1);
  std::vector<FootprintStart> sample;
  int x_begin, x_end, y_min, y_max;
  if (Mark(pixels, &x_begin, &x_end, &y_min, &y_max)) {
    const int phase = pitch_px / 2;
    // The first lattice row at or below y_min.
    const int y_first = y_min + (phase - y_min % pitch_px + pitch_px) % pitch_px;
    for (int y = y_first; y <= y_max; y += pitch_px) {
      VisitRow(y, x_begin, x_end, [&](int i, int source) {
        if ((i % cols_) % pitch_px == phase) sample.push_back(StartAt(i, source));
      });
    }
  }
  Unmark(pixels);
  return sample;
}

std::vector<FootprintStart> ThinByRank(const std::vector<FootprintStart>& sample, double every) {
  STEREORIG_CHECK(every >= 1);
  std::vector<FootprintStart> thin;
  for (double r = 0.5 * every; r < double(sample.size()); r += every) thin.push_back(sample[size_t(r)]);
  return thin;
}

std::vector<int> FootprintSampler::LatticePitchesPx() const {
  std::vector<int> ladder = {1, 2, 3, 4, 6};
  const int side = std::max(disparity_px_.cols, disparity_px_.rows);
  for (int p = 9; p <= side; p *= 2) {
    ladder.push_back(p);
    if (p * 4 / 3 <= side) ladder.push_back(p * 4 / 3);
  }
  return ladder;
}

std::vector<FootprintStart> FootprintSampler::SampleLatticeAtLeast(const std::vector<int>& pixels, int min_samples,
                                                                   int* pitch_px) {
  STEREORIG_CHECK(min_samples >= 1);
  const std::vector<int> ladder = LatticePitchesPx();
  // The valid pixels alone, N, hold about N / p^2 lattice points: start at
  // the coarsest pitch that could give min_samples and go finer while it
  // does not (a thin component holds fewer).
  size_t k = 0;
  while (k + 1 < ladder.size() &&
         double(pixels.size()) >= double(min_samples) * double(ladder[k + 1]) * double(ladder[k + 1]))
    ++k;
  for (;; --k) {
    std::vector<FootprintStart> sample = SampleLattice(pixels, ladder[k]);
    if (int(sample.size()) >= min_samples || k == 0) {
      if (pitch_px) *pitch_px = ladder[k];
      if (ladder[k] > kDensePitchPx || sample.size() <= 2 * size_t(min_samples)) return sample;
      // Windows this close overlap by 7/9 or more: thinned by rank.
      return ThinByRank(sample, double(sample.size()) / (2.0 * double(min_samples)));
    }
  }
}

}  // namespace stereorig
