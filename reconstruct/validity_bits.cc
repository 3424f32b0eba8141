#include "reconstruct/validity_bits.h"

#include <bit>
#include <cmath>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig {

ValidityBits::ValidityBits(const cv::Mat& disparity, const cv::Rect& roi)
    : roi_(roi), stride_((roi.width + 63) / 64 + 1), words_(size_t(roi.height) * size_t(stride_), 0) {
  CV_Assert(disparity.type() == CV_32FC1 && (roi & cv::Rect(0, 0, disparity.cols, disparity.rows)) == roi);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const float* row = disparity.ptr<float>(y) + roi.x;
    uint64_t* out = Row(y);
    int i = 0;
#if defined(__AVX2__)
    // Eight at a time: finite iff the exponent bits are not all set.
    const __m256i exponent = _mm256_set1_epi32(0x7f800000);
    for (; i + 8 <= roi.width; i += 8) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + i));
      const __m256i special = _mm256_cmpeq_epi32(_mm256_and_si256(v, exponent), exponent);
      const uint64_t finite = uint64_t(~_mm256_movemask_ps(_mm256_castsi256_ps(special)) & 0xff);
      out[i >> 6] |= finite << (i & 63);
    }
#endif
    for (; i < roi.width; ++i) out[i >> 6] |= uint64_t(std::isfinite(row[i])) << (i & 63);
  }
}

std::vector<cv::Point> ValidityBits::EdgePixels() const {
  std::vector<cv::Point> edge;
  const int last_word = (roi_.width - 1) >> 6;
  const uint64_t last_bit = uint64_t(1) << ((roi_.width - 1) & 63);  // the row's last pixel: no right neighbour
  const uint64_t all = ~uint64_t(0);
  for (int y = roi_.y; y < roi_.y + roi_.height; ++y) {
    const uint64_t* cur = Row(y);
    const uint64_t* above = y > roi_.y ? Row(y - 1) : nullptr;  // none: counts as all valid
    const uint64_t* below = y + 1 < roi_.y + roi_.height ? Row(y + 1) : nullptr;
    for (int k = 0; k <= last_word; ++k) {
      const uint64_t c = cur[k];
      if (c == 0) continue;
      // Bit i of each: the neighbour of the pixel at bit i is valid (or
      // outside roi).
      const uint64_t left = (c << 1) | (k == 0 ? 1 : cur[k - 1] >> 63);
      const uint64_t right = (c >> 1) | (cur[k + 1] << 63) | (k == last_word ? last_bit : 0);
      const uint64_t up = above ? above[k] : all, down = below ? below[k] : all;
      for (uint64_t e = c & ~(left & right & up & down); e != 0; e &= e - 1)
        edge.emplace_back(roi_.x + k * 64 + std::countr_zero(e), y);
    }
  }
  return edge;
}

}  // namespace stereorig
