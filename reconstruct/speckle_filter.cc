#include "reconstruct/speckle_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "calib/core/input_error.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig {
namespace {

// Union-find over provisional labels 1..: parent[i] <= i always (a union
// hangs the larger root under the smaller), so a root is its set's smallest
// label and one pass in increasing order flattens every chain.
struct Labels {
  std::vector<int32_t> parent{0};  // label 0: no blob (invalid pixel)
  std::vector<int32_t> count{0};   // pixels given each provisional label

  int32_t New() {
    const int32_t l = int32_t(parent.size());
    parent.push_back(l);
    count.push_back(0);
    return l;
  }
  int32_t Root(int32_t l) {
    while (parent[l] != l) l = parent[l] = parent[parent[l]];  // path halving
    return l;
  }
  int32_t Join(int32_t a, int32_t b) {
    a = Root(a), b = Root(b);
    if (a == b) return a;
    if (a > b) std::swap(a, b);
    parent[b] = a;
    return a;
  }
};

// f[i] = d[i] in 1/16 px, clamped to +-32000 and rounded half away from
// zero (d * 16 has at most 24 significant bits, so adding 0.5 is exact), or
// `invalid` where d[i] is not finite.
void ToSixteenths(const float* d, int n, int16_t invalid, int16_t* f) {
  int i = 0;
#if defined(__AVX2__)
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  const __m256 inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const __m256d sixteen = _mm256_set1_pd(16.0), lo = _mm256_set1_pd(-32000.0), hi = _mm256_set1_pd(32000.0);
  const __m256d sign = _mm256_set1_pd(-0.0), half = _mm256_set1_pd(0.5);
  auto round4 = [&](__m128 v) {
    const __m256d s = _mm256_min_pd(_mm256_max_pd(_mm256_mul_pd(_mm256_cvtps_pd(v), sixteen), lo), hi);
    return _mm256_cvttpd_epi32(_mm256_add_pd(s, _mm256_or_pd(_mm256_and_pd(s, sign), half)));  // int(): truncates
  };
  for (; i + 8 <= n; i += 8) {
    const __m256 v = _mm256_loadu_ps(d + i);
    const __m256i finite = _mm256_castps_si256(_mm256_cmp_ps(_mm256_and_ps(v, abs_mask), inf, _CMP_LT_OQ));
    const __m128i values = _mm_packs_epi32(round4(_mm256_castps256_ps128(v)), round4(_mm256_extractf128_ps(v, 1)));
    const __m128i keep = _mm_packs_epi32(_mm256_castsi256_si128(finite), _mm256_extracti128_si256(finite, 1));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(f + i), _mm_blendv_epi8(_mm_set1_epi16(invalid), values, keep));
  }
#endif
  for (; i < n; ++i) {
    if (!std::isfinite(d[i])) {
      f[i] = invalid;
      continue;
    }
    const double sixteenths = std::clamp(d[i] * 16.0, -32000.0, 32000.0);
    f[i] = int16_t(int(sixteenths + std::copysign(0.5, sixteenths)));
  }
}

}  // namespace

void FilterSpeckles16(cv::Mat disparity_16, int16_t invalid, int max_blob_px, int max_diff, const cv::Mat& step_left_16,
                      const cv::Mat& step_up_16) {
  STEREORIG_CHECK(disparity_16.type() == CV_16SC1 && max_diff >= 0);
  const bool steps = !step_left_16.empty();
  STEREORIG_CHECK(step_left_16.empty() == step_up_16.empty());
  STEREORIG_CHECK(!steps || (step_left_16.type() == CV_16SC1 && step_up_16.type() == CV_16SC1 &&
                             step_left_16.size() == disparity_16.size() && step_up_16.size() == disparity_16.size()));
  // 16-bit values differ by at most 65535: a larger reach joins the same
  // neighbours, and the clamp keeps `a - b + max_diff` below int's range.
  max_diff = std::min(max_diff, 65535);
  if (max_blob_px <= 0 || disparity_16.empty()) return;
  const int w = disparity_16.cols, h = disparity_16.rows;
  const std::unique_ptr<int32_t[]> label(new int32_t[size_t(w) * h]);  // every element written below
  Labels sets;
  // |a - b| <= max_diff as one unsigned comparison (a, b: 16-bit values
  // and steps, so a - b + max_diff stays within int).
  const unsigned reach = 2u * unsigned(max_diff);
  auto near = [&](int a, int b) { return unsigned(a - b + max_diff) <= reach; };
  // Pass 1: each valid pixel joins its left and upper neighbours' blobs
  // where it is within max_diff of them. The left neighbour's label and
  // value stay in registers; the first row has no upper one.
  auto label_row = [&](int y, auto has_up) {
    const int16_t* d = disparity_16.ptr<int16_t>(y);
    const int16_t* up = has_up ? disparity_16.ptr<int16_t>(y - 1) : nullptr;
    const int16_t* step_left = steps ? step_left_16.ptr<int16_t>(y) : nullptr;
    const int16_t* step_up = steps ? step_up_16.ptr<int16_t>(y) : nullptr;
    int32_t* l = label.get() + size_t(y) * w;
    const int32_t* lu = l - (has_up ? w : 0);
    int32_t left = 0;
    int left_v = 0;
    for (int x = 0; x < w; ++x) {
      const int v = d[x];
      if (v == invalid) {
        l[x] = left = 0;
        continue;
      }
      int32_t mine = left != 0 && near(v - (steps ? step_left[x] : 0), left_v) ? left : 0;
      if constexpr (decltype(has_up)::value) {
        const int32_t u = lu[x];
        if (u != 0 && near(v - (steps ? step_up[x] : 0), up[x])) mine = mine == 0 || mine == u ? u : sets.Join(mine, u);
      }
      if (mine == 0) mine = sets.New();
      l[x] = left = mine;
      left_v = v;
      ++sets.count[mine];
    }
  };
  label_row(0, std::false_type());
  for (int y = 1; y < h; ++y) label_row(y, std::true_type());
  // Blob sizes on the roots; then whether each provisional label's blob goes.
  const int n = int(sets.parent.size());
  std::vector<int32_t> size(n, 0);
  for (int i = 1; i < n; ++i) {
    sets.parent[i] = sets.parent[sets.parent[i]];  // parent[i] < i is already a root
    size[sets.parent[i]] += sets.count[i];
  }
  std::vector<uint8_t> drop(n, 0);
  bool any = false;
  for (int i = 1; i < n; ++i) any |= (drop[i] = size[sets.parent[i]] <= max_blob_px);
  if (!any) return;
  for (int y = 0; y < h; ++y) {
    int16_t* d = disparity_16.ptr<int16_t>(y);
    const int32_t* l = label.get() + size_t(y) * w;
    for (int x = 0; x < w; ++x)
      if (drop[l[x]]) d[x] = invalid;
  }
}

namespace {

// The reach in sixteenths of a pixel; 4096 px already joins any two 16-bit
// values. One rule for the filter and for the steps it is given, so that
// where no step passes the reach the filter is the plain one.
int ReachSixteenths(double max_diff_px) { return int(std::lround(std::min(max_diff_px, 4096.0) * 16)); }

// RemoveSpeckleBlobs, with FilterSpeckles16's steps (empty: none).
void RemoveBlobs(cv::Mat disparity_px, int max_blob_px, double max_diff_px, const cv::Mat& step_left_16,
                 const cv::Mat& step_up_16) {
  STEREORIG_CHECK(disparity_px.type() == CV_32FC1 && max_diff_px >= 0);
  const int max_diff_16 = ReachSixteenths(max_diff_px);
  constexpr int16_t kInvalid = std::numeric_limits<int16_t>::min();
  cv::Mat fixed(disparity_px.size(), CV_16SC1);
  for (int y = 0; y < disparity_px.rows; ++y)
    ToSixteenths(disparity_px.ptr<float>(y), disparity_px.cols, kInvalid, fixed.ptr<int16_t>(y));
  FilterSpeckles16(fixed, kInvalid, max_blob_px, max_diff_16, step_left_16, step_up_16);
  for (int y = 0; y < disparity_px.rows; ++y) {
    float* d = disparity_px.ptr<float>(y);
    const int16_t* f = fixed.ptr<int16_t>(y);
    for (int x = 0; x < disparity_px.cols; ++x)
      if (f[x] == kInvalid) d[x] = std::numeric_limits<float>::infinity();
  }
}

}  // namespace

void RemoveSpeckleBlobs(cv::Mat disparity_px, int max_blob_px, double max_diff_px) {
  RemoveBlobs(disparity_px, max_blob_px, max_diff_px, cv::Mat(), cv::Mat());
}

void RemoveSpeckleBlobsAlongSlopes(cv::Mat disparity_px, const cv::Mat& slope_x, const cv::Mat& slope_y,
                                   int max_blob_px, double max_diff_px) {
  STEREORIG_CHECK(slope_x.type() == CV_32FC1 && slope_y.type() == CV_32FC1 && slope_x.size() == disparity_px.size() &&
                  slope_y.size() == disparity_px.size());
  if (max_blob_px <= 0 || disparity_px.empty()) return;
  // The step from the left (upper) neighbour a to b, in sixteenths: their
  // mean slope where each one's slope steps beyond the reach, the same way
  // (|slope| <= 2000 px/px keeps it within 16 bits); else 0.
  const double reach_16 = ReachSixteenths(max_diff_px);
  auto sixteenths = [&](float a, float b) {
    const double a_16 = 16.0 * double(a), b_16 = 16.0 * double(b);
    const bool steep = (a_16 > reach_16 && b_16 > reach_16) || (a_16 < -reach_16 && b_16 < -reach_16);
    if (!steep || !std::isfinite(a_16 + b_16)) return int16_t(0);
    return int16_t(std::lround(std::clamp(0.5 * (a_16 + b_16), -32000.0, 32000.0)));
  };
  cv::Mat step_left(disparity_px.size(), CV_16SC1, cv::Scalar(0)),
      step_up(disparity_px.size(), CV_16SC1, cv::Scalar(0));
  for (int y = 0; y < disparity_px.rows; ++y) {
    const float* gx = slope_x.ptr<float>(y);
    const float* gy = slope_y.ptr<float>(y);
    const float* gy_up = y > 0 ? slope_y.ptr<float>(y - 1) : nullptr;
    int16_t* left = step_left.ptr<int16_t>(y);
    int16_t* up = step_up.ptr<int16_t>(y);
    for (int x = 1; x < disparity_px.cols; ++x) left[x] = sixteenths(gx[x - 1], gx[x]);
    if (gy_up)
      for (int x = 0; x < disparity_px.cols; ++x) up[x] = sixteenths(gy_up[x], gy[x]);
  }
  RemoveBlobs(disparity_px, max_blob_px, max_diff_px, step_left, step_up);
}

}  // namespace stereorig
