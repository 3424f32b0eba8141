#include "reconstruct/kernel_correlation.h"

#include <algorithm>
#include <cmath>

#include "calib/core/input_error.h"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace stereorig {
namespace {

constexpr int kMaxTaps = 64;  // the surface fit's kernels have <= 61 taps (half width <= 30)

// out[x] = the chain over k < n of fma(src[k][x], value[k], .) from 0, for
// x in [x_begin, x_end): the chains of 8 (AVX2) or 1 outputs at a time, each
// kept in a register over all taps.
void Chains(const float* const* src, const float* value, int n, int x_begin, int x_end, float* out) {
  int x = x_begin;
#if defined(__AVX2__) && defined(__FMA__)
  __m256 tap[kMaxTaps];
  for (int k = 0; k < n; ++k) tap[k] = _mm256_set1_ps(value[k]);
  for (; x + 16 <= x_end; x += 16) {  // two independent chains hide the FMA latency
    __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps();
    for (int k = 0; k < n; ++k) {
      s0 = _mm256_fmadd_ps(_mm256_loadu_ps(src[k] + x), tap[k], s0);
      s1 = _mm256_fmadd_ps(_mm256_loadu_ps(src[k] + x + 8), tap[k], s1);
    }
    _mm256_storeu_ps(out + x, s0);
    _mm256_storeu_ps(out + x + 8, s1);
  }
  for (; x + 8 <= x_end; x += 8) {
    __m256 s = _mm256_setzero_ps();
    for (int k = 0; k < n; ++k) s = _mm256_fmadd_ps(_mm256_loadu_ps(src[k] + x), tap[k], s);
    _mm256_storeu_ps(out + x, s);
  }
#endif
  for (; x < x_end; ++x) {
    float s = 0;
    for (int k = 0; k < n; ++k) s = std::fma(src[k][x], value[k], s);
    out[x] = s;
  }
}

}  // namespace

KernelTaps NonzeroTaps(const float* taps, int half) {
  STEREORIG_CHECK(half >= 0 && 2 * half + 1 <= kMaxTaps);
  KernelTaps k;
  for (int u = -half; u <= half; ++u)
    if (taps[u + half] != 0) k.value.push_back(taps[u + half]), k.offset.push_back(u);
  return k;
}

void CorrelateAlongRow(const float* in, int width, const KernelTaps& taps, float* out) {
  const int n = int(taps.value.size());
  if (n == 0) {
    std::fill(out, out + width, 0.0f);
    return;
  }
  // Inside [x_begin, x_end) every tap reads inside the row; nearer the
  // ends, the taps that would read beyond it are left out of the chain.
  const int x_begin = std::min(width, std::max(0, -taps.offset.front()));
  const int x_end = std::max(x_begin, width - std::max(0, taps.offset.back()));
  auto near_end = [&](int x) {
    float s = 0;
    for (int k = 0; k < n; ++k) {
      const int i = x + taps.offset[size_t(k)];
      if (i >= 0 && i < width) s = std::fma(in[i], taps.value[size_t(k)], s);
    }
    out[x] = s;
  };
  for (int x = 0; x < x_begin; ++x) near_end(x);
  const float* src[kMaxTaps] = {};
  for (int k = 0; k < n; ++k) src[k] = in + taps.offset[size_t(k)];
  Chains(src, taps.value.data(), n, x_begin, x_end, out);
  for (int x = x_end; x < width; ++x) near_end(x);
}

void CorrelateDownColumns(const float* in, long stride, int rows, int y, int width, const KernelTaps& taps,
                          float* out) {
  // The taps whose rows are inside the stack, in order.
  const float* src[kMaxTaps] = {};
  float value[kMaxTaps] = {};
  int n = 0;
  for (size_t k = 0; k < taps.value.size(); ++k) {
    const int r = y + taps.offset[k];
    if (r < 0 || r >= rows) continue;
    src[n] = in + r * stride, value[n] = taps.value[k];
    ++n;
  }
  Chains(src, value, n, 0, width, out);
}

}  // namespace stereorig
