#include "reconstruct/lit_mask.h"

#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig {

// Built with -ffp-contract=off (reconstruct/CMakeLists.txt): no FMA may
// fuse mean2 - mean * mean, whose float product boxFilter's users round
// first (also in the AVX2 loop: GCC's intrinsics are plain vector
// arithmetic, which it would otherwise contract).
cv::Mat LitMask(const cv::Mat& grey, double contrast_dn) {
  STEREORIG_CHECK(grey.type() == CV_8UC1);
  constexpr int kHalf = kLitWindowHalfPx;
  const int w = grey.cols, h = grey.rows;
  cv::Mat lit(grey.size(), CV_8UC1, cv::Scalar(0));
  if (w == 0 || h == 0) return lit;
  // Reflected column and row of every window position (index + kHalf).
  std::vector<int> col(w + 2 * kHalf), row(h + 2 * kHalf);
  for (int i = 0; i < w + 2 * kHalf; ++i) col[i] = cv::borderInterpolate(i - kHalf, w, cv::BORDER_REFLECT_101);
  for (int i = 0; i < h + 2 * kHalf; ++i) row[i] = cv::borderInterpolate(i - kHalf, h, cv::BORDER_REFLECT_101);
  // Column sums of g and g^2 over the window's 9 rows, at every padded column.
  std::vector<int32_t> sum(w + 2 * kHalf, 0), sum2(w + 2 * kHalf, 0);
  auto add_row = [&](int r, int sign) {
    const uint8_t* g = grey.ptr<uint8_t>(r);
    for (int i = 0; i < w + 2 * kHalf; ++i) {
      const int32_t v = g[col[i]];
      sum[i] += sign * v;
      sum2[i] += sign * v * v;
    }
  };
  for (int k = 0; k < 2 * kHalf + 1; ++k) add_row(row[k], 1);
  const float threshold = float(contrast_dn * contrast_dn);
  const double scale = 1.0 / ((2 * kHalf + 1) * (2 * kHalf + 1));  // boxFilter's, applied to its double sums
  // Prefix sums of the column sums along the row: the window sum at x is
  // prefix[x + 9] - prefix[x]. Unsigned, wrapping: the difference is exact
  // whatever the row's total (a window's sums are < 81 * 255^2).
  std::vector<uint32_t> prefix(w + 2 * kHalf + 1), prefix2(w + 2 * kHalf + 1);
  constexpr int kWindow = 2 * kHalf + 1;
  // Whether the window at x is lit: the two means rounded to float as
  // boxFilter rounds them, the variance formed in float.
  auto lit_at = [&](int x) {
    const float mean = float(int32_t(prefix[x + kWindow] - prefix[x]) * scale);
    const float mean2 = float(int32_t(prefix2[x + kWindow] - prefix2[x]) * scale);
    const float square = mean * mean;
    return mean2 - square > threshold;
  };
  for (int y = 0; y < h; ++y) {
    if (y > 0) add_row(row[y + 2 * kHalf], 1), add_row(row[y - 1], -1);
    for (int i = 0; i < w + 2 * kHalf; ++i)
      prefix[i + 1] = prefix[i] + uint32_t(sum[i]), prefix2[i + 1] = prefix2[i] + uint32_t(sum2[i]);
    uint8_t* out = lit.ptr<uint8_t>(y);
    int x = 0;
#if defined(__AVX2__)
    // 8 pixels at a time, the same operations in the same precision.
    const __m256d vscale = _mm256_set1_pd(scale);
    const __m256 vthreshold = _mm256_set1_ps(threshold);
    auto means = [&](const std::vector<uint32_t>& p, int x0) {
      const __m256i sums =
          _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p.data() + x0 + kWindow)),
                           _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p.data() + x0)));
      const __m128 lo = _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(sums)), vscale));
      const __m128 hi = _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(sums, 1)), vscale));
      return _mm256_set_m128(hi, lo);
    };
    for (; x + 8 <= w; x += 8) {
      const __m256 mean = means(prefix, x), mean2 = means(prefix2, x);
      const __m256 var = _mm256_sub_ps(mean2, _mm256_mul_ps(mean, mean));  // no FMA: -ffp-contract=off
      const __m256i lit8 = _mm256_castps_si256(_mm256_cmp_ps(var, vthreshold, _CMP_GT_OQ));
      const __m128i words = _mm_packs_epi32(_mm256_castsi256_si128(lit8), _mm256_extracti128_si256(lit8, 1));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(out + x), _mm_packs_epi16(words, words));  // -1 = 255
    }
#endif
    for (; x < w; ++x) out[x] = lit_at(x) ? 255 : 0;
  }
  return lit;
}

cv::Mat LitWindowOnData(const cv::Mat& valid) {
  STEREORIG_CHECK(valid.type() == CV_8UC1);
  cv::Mat on_data;
  // erode's default border is the largest value: outside the image is data.
  cv::erode(valid != 0, on_data,
            cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kLitWindowHalfPx + 1, 2 * kLitWindowHalfPx + 1)));
  return on_data;
}

}  // namespace stereorig
