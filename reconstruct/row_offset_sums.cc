#include "reconstruct/row_offset_sums.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig {

#if !defined(__AVX2__)
namespace {

// One sample, as row_offset_refine.cc summed it before session 8.
inline void AddSample(const float* l, const float* const rk[4], const float* const gk[4], const double w[4],
                      const double dw[4], double gain, double offset, int s, RowOffsetSums* t) {
  double r = 0, rx = 0, ry = 0;
  for (int k = 0; k < 4; ++k) r += w[k] * rk[k][s], rx += w[k] * gk[k][s], ry += dw[k] * rk[k][s];
  const double e = l[s] - gain * r - offset;
  t->sxx += rx * rx, t->sxy += rx * ry, t->sxr += rx * r, t->sx += rx;
  t->syy += ry * ry, t->syr += ry * r, t->sy += ry;
  t->srr += r * r, t->sr += r;
  t->sxe += rx * e, t->sye += ry * e, t->sre += r * e, t->se += e;
  t->slr += l[s] * r;
}

}  // namespace
#endif

RowOffsetSums RowOffsetPassSums(const float* l, const float* const rk[4], const float* const gk[4], const double w[4],
                                const double dw[4], double gain, double offset, int n) {
  RowOffsetSums t;
#if defined(__AVX2__)
  // Per 4 samples: r, rx, ry, e and l r in lanes (the plain loop's
  // operations, lane by lane), transposed to one register per sample
  // (rx, ry, r, e); then per sample, in order, the products of 4 lane
  // permutations added to the accumulators
  //   a = (sxx, sxy, sxr, syy) += (rx, rx, rx, ry) (rx, ry, r, ry)
  //   b = (syr, srr, sxe, sye) += (ry, r, rx, ry) (r, r, e, e)
  //   c = (sre, sx, sy, sr)    += (r, rx, ry, r) (e, 1, 1, 1)
  //   d = (se, slr)            += (e, l r)
  // (x * 1 is x exactly, so sx, sy, sr get the plain loop's additions).
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const __m256d vgain = _mm256_set1_pd(gain), voffset = _mm256_set1_pd(offset);
  __m256d a = zero, b = zero, c = zero;
  __m128d d = _mm_setzero_pd();
  for (int s0 = 0; s0 < n; s0 += 4) {
    __m256d r = zero, rx = zero, ry = zero;
    for (int k = 0; k < 4; ++k) {
      const __m256d rv = _mm256_cvtps_pd(_mm_loadu_ps(rk[k] + s0)), gv = _mm256_cvtps_pd(_mm_loadu_ps(gk[k] + s0));
      r = _mm256_add_pd(r, _mm256_mul_pd(_mm256_set1_pd(w[k]), rv));
      rx = _mm256_add_pd(rx, _mm256_mul_pd(_mm256_set1_pd(w[k]), gv));
      ry = _mm256_add_pd(ry, _mm256_mul_pd(_mm256_set1_pd(dw[k]), rv));
    }
    const __m256d lv = _mm256_cvtps_pd(_mm_loadu_ps(l + s0));
    const __m256d e = _mm256_sub_pd(_mm256_sub_pd(lv, _mm256_mul_pd(vgain, r)), voffset);
    const __m256d lr = _mm256_mul_pd(lv, r);
    // Transpose (rx, ry, r, e) x 4 samples to 4 samples x (rx, ry, r, e).
    const __m256d t0 = _mm256_unpacklo_pd(rx, ry), t1 = _mm256_unpackhi_pd(rx, ry);  // (rx0 ry0 rx2 ry2), (rx1 ry1 ..)
    const __m256d t2 = _mm256_unpacklo_pd(r, e), t3 = _mm256_unpackhi_pd(r, e);      // (r0 e0 r2 e2), (r1 e1 ..)
    __m256d p[4];
    p[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    p[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    p[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    p[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
    const __m256d el0 = _mm256_unpacklo_pd(e, lr), el1 = _mm256_unpackhi_pd(e, lr);  // (e0 lr0 e2 lr2), (e1 lr1 ..)
    __m128d q[4];
    q[0] = _mm256_castpd256_pd128(el0);
    q[1] = _mm256_castpd256_pd128(el1);
    q[2] = _mm256_extractf128_pd(el0, 1);
    q[3] = _mm256_extractf128_pd(el1, 1);
    const int m = n - s0 < 4 ? n - s0 : 4;
    for (int j = 0; j < m; ++j) {
      const __m256d v = p[j];  // (rx, ry, r, e)
      a = _mm256_add_pd(a, _mm256_mul_pd(_mm256_permute4x64_pd(v, 0x40), _mm256_permute4x64_pd(v, 0x64)));
      b = _mm256_add_pd(b, _mm256_mul_pd(_mm256_permute4x64_pd(v, 0x49), _mm256_permute4x64_pd(v, 0xfa)));
      c = _mm256_add_pd(
          c, _mm256_mul_pd(_mm256_permute4x64_pd(v, 0x92), _mm256_blend_pd(_mm256_permute4x64_pd(v, 0x03), one, 0xe)));
      d = _mm_add_pd(d, q[j]);
    }
  }
  alignas(32) double out[14];
  _mm256_store_pd(out, a);
  _mm256_store_pd(out + 4, b);
  _mm256_store_pd(out + 8, c);
  _mm_store_pd(out + 12, d);
  t.sxx = out[0], t.sxy = out[1], t.sxr = out[2], t.syy = out[3];
  t.syr = out[4], t.srr = out[5], t.sxe = out[6], t.sye = out[7];
  t.sre = out[8], t.sx = out[9], t.sy = out[10], t.sr = out[11];
  t.se = out[12], t.slr = out[13];
#else
  for (int s = 0; s < n; ++s) AddSample(l, rk, gk, w, dw, gain, offset, s, &t);
#endif
  return t;
}

}  // namespace stereorig
