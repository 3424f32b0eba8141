#include "reconstruct/local_plane.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include "calib/core/input_error.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig {

namespace internal {

void SolveLdlt3(const double m[3][3], const double b[3], double p[3]) {
  // The factorisation in place (Eigen's ldlt_inplace<Lower>::unblocked):
  // a[i][j], i > j, becomes L, a[i][i] D.
  double a[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) a[i][j] = m[i][j];
  int transposition[3];
  for (int k = 0; k < 3; ++k) {
    // The largest remaining diagonal entry in magnitude, the first of equals.
    int biggest = k;
    for (int i = k + 1; i < 3; ++i)
      if (std::abs(a[i][i]) > std::abs(a[biggest][biggest])) biggest = i;
    transposition[k] = biggest;
    if (biggest != k) {
      for (int j = 0; j < k; ++j) std::swap(a[k][j], a[biggest][j]);
      for (int i = biggest + 1; i < 3; ++i) std::swap(a[i][k], a[i][biggest]);
      std::swap(a[k][k], a[biggest][biggest]);
      for (int i = k + 1; i < biggest; ++i) std::swap(a[i][k], a[biggest][i]);
    }
    if (k == 1) {
      const double t0 = a[0][0] * a[1][0];
      a[1][1] -= a[1][0] * t0;
      a[2][1] -= a[2][0] * t0;
    } else if (k == 2) {
      const double t0 = a[0][0] * a[2][0], t1 = a[1][1] * a[2][1];
      a[2][2] -= a[2][0] * t0 + a[2][1] * t1;
    }
    // A zero pivot leaves its column as it is (Eigen: no division).
    if (k < 2 && std::abs(a[k][k]) > 0)
      for (int i = k + 1; i < 3; ++i) a[i][k] /= a[k][k];
  }
  // The solve (Eigen's LDLT::_solve_impl_transposed): P, L^-1, D^+, L^-T, P^T.
  double x[3] = {b[0], b[1], b[2]};
  for (int k = 0; k < 3; ++k) std::swap(x[k], x[transposition[k]]);
  x[1] -= a[1][0] * x[0];
  x[2] -= a[2][0] * x[0] + a[2][1] * x[1];
  for (int i = 0; i < 3; ++i) x[i] = std::abs(a[i][i]) > std::numeric_limits<double>::min() ? x[i] / a[i][i] : 0.0;
  x[1] -= a[2][1] * x[2];
  x[0] -= a[1][0] * x[1] + a[2][0] * x[2];
  for (int k = 2; k >= 0; --k) std::swap(x[k], x[transposition[k]]);
  p[0] = x[0], p[1] = x[1], p[2] = x[2];
}

}  // namespace internal

namespace {

// The window's moments: pixel counts (ints, exact) and disparity sums.
struct Moments {
  int n = 0, nx = 0, ny = 0, nxx = 0, nyy = 0, nxy = 0;
  double sd = 0, sxd = 0, syd = 0;
};

// Window rows v0..v1, columns u0..u1 around q (roi-clipped).
struct Window {
  int v0, v1, u0, u1;
};

// The sums in raster order, one valid pixel at a time: the order they were
// always added in (u * d and v * d are float products).
Moments SumInOrder(const cv::Mat& disparity, const ValidityBits& valid, cv::Point q, const Window& w) {
  Moments m;
  for (int v = w.v0; v <= w.v1; ++v) {
    uint64_t bits = valid.Span(q.x + w.u0, q.y + v, w.u1 - w.u0 + 1);
    if (bits == 0) continue;
    const float* row = disparity.ptr<float>(q.y + v) + q.x;
    int count = 0, su = 0, suu = 0;
    for (; bits != 0; bits &= bits - 1) {
      const int u = w.u0 + std::countr_zero(bits);
      const float d = row[u];
      ++count, su += u, suu += u * u;
      m.sd += d, m.sxd += u * d, m.syd += v * d;
    }
    m.n += count, m.nx += su, m.ny += v * count, m.nxx += suu, m.nyy += v * v * count, m.nxy += v * su;
  }
  return m;
}

#if defined(__AVX2__)
// Disparities whose sums are exact in doubles, in any order: 0 or
// 2^-8 <= |d| < 2^9. Each term (d, or the float products u d, v d with
// |u|, |v| <= 10) is then a multiple of 2^-31 and the window's at most 441
// of them sum to less than 441 * 10 * 2^9 < 2^22 in magnitude, so every
// partial sum fits a double's 53 bits: no addition rounds, and eight
// columns at a time give the raster order's bits.
constexpr float kExactMin = 1.0f / 256, kExactMax = 512;

// The window's moments, eight columns at a time; false (m unspecified) if a
// valid disparity lies outside the exact range.
bool SumExact(const cv::Mat& disparity, const ValidityBits& valid, cv::Point q, const Window& w, Moments* m) {
  const int width = w.u1 - w.u0 + 1;
  const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 sign = _mm256_set1_ps(-0.0f), low = _mm256_set1_ps(kExactMin), high = _mm256_set1_ps(kExactMax);
  const __m256 zero = _mm256_setzero_ps();
  // Per lane: sum u, sum u^2, sum u v (the rows' counts come from their bits).
  __m256i su = _mm256_setzero_si256(), suu = su, suv = su;
  __m256d sd = _mm256_setzero_pd(), sxd = sd, syd = sd;
  __m256 outside = zero;
  int n = 0, ny = 0, nyy = 0;
  const size_t step = disparity.step[0];
  const uchar* first_row = disparity.ptr<uchar>(q.y + w.v0) + sizeof(float) * size_t(q.x + w.u0);
  for (int v = w.v0; v <= w.v1; ++v) {
    const uint64_t bits = valid.Span(q.x + w.u0, q.y + v, width);
    if (bits == 0) continue;
    const int count = std::popcount(bits);
    n += count, ny += v * count, nyy += v * v * count;
    const float* row = reinterpret_cast<const float*>(first_row + step * size_t(v - w.v0));
    const __m256i vv = _mm256_set1_epi32(v);
    const __m256 fv = _mm256_set1_ps(float(v));
    for (int c = 0; c < width; c += 8) {
      const uint32_t chunk = uint32_t(bits >> c) & 0xff;
      if (chunk == 0) continue;
      const __m256i on = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(chunk)), lane_bit), lane_bit);
      // Lanes off (empty or past the window) read as 0 and add nothing.
      const __m256 d = _mm256_maskload_ps(row + c, on);
      const __m256i u = _mm256_and_si256(_mm256_add_epi32(lane, _mm256_set1_epi32(w.u0 + c)), on);
      su = _mm256_add_epi32(su, u);
      suu = _mm256_add_epi32(suu, _mm256_mullo_epi32(u, u));
      suv = _mm256_add_epi32(suv, _mm256_mullo_epi32(u, vv));
      const __m256 a = _mm256_andnot_ps(sign, d);
      outside = _mm256_or_ps(
          outside, _mm256_or_ps(_mm256_and_ps(_mm256_cmp_ps(a, low, _CMP_LT_OQ), _mm256_cmp_ps(a, zero, _CMP_NEQ_OQ)),
                                _mm256_cmp_ps(a, high, _CMP_GE_OQ)));
      const __m256 ud = _mm256_mul_ps(_mm256_cvtepi32_ps(u), d), vd = _mm256_mul_ps(fv, d);
      sd = _mm256_add_pd(
          sd, _mm256_add_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(d)), _mm256_cvtps_pd(_mm256_extractf128_ps(d, 1))));
      sxd = _mm256_add_pd(sxd, _mm256_add_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(ud)),
                                             _mm256_cvtps_pd(_mm256_extractf128_ps(ud, 1))));
      syd = _mm256_add_pd(syd, _mm256_add_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(vd)),
                                             _mm256_cvtps_pd(_mm256_extractf128_ps(vd, 1))));
    }
  }
  if (_mm256_movemask_ps(outside) != 0) return false;
  // Lanes summed: [su, suu, suv, 0] and [sd, sxd, syd, 0].
  const __m256i hi = _mm256_hadd_epi32(_mm256_hadd_epi32(su, suu), _mm256_hadd_epi32(suv, _mm256_setzero_si256()));
  alignas(16) int32_t ints[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(ints),
                  _mm_add_epi32(_mm256_castsi256_si128(hi), _mm256_extracti128_si256(hi, 1)));
  m->n = n, m->ny = ny, m->nyy = nyy;
  m->nx = ints[0], m->nxx = ints[1], m->nxy = ints[2];
  const __m256d a = _mm256_hadd_pd(sd, sxd), b = _mm256_hadd_pd(syd, _mm256_setzero_pd());
  // a = [sd01, sxd01, sd23, sxd23], b = [syd01, 0, syd23, 0]
  alignas(32) double sums[4];
  _mm256_store_pd(sums, _mm256_add_pd(_mm256_permute2f128_pd(a, b, 0x20), _mm256_permute2f128_pd(a, b, 0x31)));
  m->sd = sums[0], m->sxd = sums[1], m->syd = sums[2];
  return true;
}
#endif

}  // namespace

bool FitLocalPlane(const cv::Mat& disparity, const ValidityBits& valid, const cv::Rect& roi, cv::Point q, int r,
                   LocalPlane* plane) {
  // The exact-sum bound (local_plane.h) and Span's 64-bit words hold for r <= 10.
  STEREORIG_CHECK(r >= 1 && r <= 10);
  const Window w{std::max(-r, roi.y - q.y), std::min(r, roi.y + roi.height - 1 - q.y), std::max(-r, roi.x - q.x),
                 std::min(r, roi.x + roi.width - 1 - q.x)};
  Moments m;
#if defined(__AVX2__)
  if (!SumExact(disparity, valid, q, w, &m)) m = SumInOrder(disparity, valid, q, w);  // rare
#else
  m = SumInOrder(disparity, valid, q, w);
#endif
  if (m.n < 6) return false;
  const double s1 = m.n, sx = m.nx, sy = m.ny, sxx = m.nxx, syy = m.nyy, sxy = m.nxy;
  // The 3x3 determinant; its products of moments stay below 2^53, so it is
  // exact (whatever the order).
  const double det = s1 * (sxx * syy - sxy * sxy) - sx * (sx * syy - sy * sxy) + sy * (sx * sxy - sy * sxx);
  if (std::abs(det) < 1e-6 * s1 * s1 * s1) return false;
  const double mat[3][3] = {{s1, sx, sy}, {sx, sxx, sxy}, {sy, sxy, syy}};
  const double b[3] = {m.sd, m.sxd, m.syd};
  double p[3];
  internal::SolveLdlt3(mat, b, p);
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return false;
  *plane = {p[0], p[1], p[2]};
  return true;
}

}  // namespace stereorig
