// The AVX2 kernels of the sub-pixel window (subpixel_window.h), for the
// files built with -march=native only: subpixel_window.cc, and
// subpixel_refine.cc, whose Gauss-Newton loop inlines the pass (a call
// there spilled every double live across it and paid the pass's prologue:
// ~50 instructions a pass).
//
// Internal linkage, as lanczos_taps.h's SampleLanczos: each file compiles
// its own copy, so no file can be handed another's copy built with other
// flags. The arithmetic is the same in every copy: no plain multiply here
// feeds a plain add (each product goes to an hadd or is an explicit FMA),
// so there is nothing GCC could contract differently in one copy; keep it
// so when editing (GCC does fuse _mm256_mul_ps into _mm256_add_ps).
#pragma once

#if !defined(__AVX2__)
#error "subpixel_window_avx2.h is for files built with AVX2 (STEREORIG_NATIVE)"
#endif

#include <immintrin.h>

#include <cstdint>

#include "reconstruct/lanczos_taps.h"
#include "reconstruct/subpixel_window.h"

namespace stereorig {
namespace {

// Lane k of the result: the sum of the 8 lanes of a[k].
inline __m256 TransposeSum8(const __m256 a[8]) {
  const __m256 q0 = _mm256_hadd_ps(_mm256_hadd_ps(a[0], a[1]), _mm256_hadd_ps(a[2], a[3]));
  const __m256 q1 = _mm256_hadd_ps(_mm256_hadd_ps(a[4], a[5]), _mm256_hadd_ps(a[6], a[7]));
  return _mm256_add_ps(_mm256_permute2f128_ps(q0, q1, 0x20), _mm256_permute2f128_ps(q0, q1, 0x31));
}

// TransposeSum8 of a[0..3] and four zero vectors, without summing the
// zeros: lane k < 4 the sum of the 8 lanes of a[k], in the same order (so
// the same float), lanes 4..7 zero. For a last chunk of at most 4 samples.
inline __m256 TransposeSum4(const __m256 a[4]) {
  const __m256 q0 = _mm256_hadd_ps(_mm256_hadd_ps(a[0], a[1]), _mm256_hadd_ps(a[2], a[3]));
  return _mm256_zextps128_ps256(_mm_add_ps(_mm256_castps256_ps128(q0), _mm256_extractf128_ps(q0, 1)));
}

// The sum of the 8 lanes, in double.
inline double HorizontalSum(__m256 a) {
  const __m128 s4 = _mm_add_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
  const __m128 s2 = _mm_add_ps(s4, _mm_movehl_ps(s4, s4));
  return _mm_cvtss_f32(_mm_add_ss(s2, _mm_movehdup_ps(s2)));
}

// All ones in the first `valid` lanes (0..8), zero after.
inline __m256 LeadingMask(int valid) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  return _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(valid), lane));
}

// The Lanczos values r and slopes g of the first `valid` (1..8) of 8
// samples at right columns base + offset[k] of the rows at byte offsets
// row[k] + row_shift from `right`; the other lanes' are 0.
// `table`: LanczosTapTable(), looked up once per thread (WindowLanes; a
// function-local static's guard and call per chunk cost ~8 % of the pass,
// once per pass still ~3 %).
// The columns and table entries are handed to the scalar loads as unsigned
// 32-bit (both are >= 0: the caller checks the reach), which the
// extraction zero-extends for free, and an entry as its byte offset: no
// sign extension or scaling per sample (~25 of a chunk's ~140
// instructions).
// kLanes: 8, or 4 where valid <= 4 (a window's last chunk, e.g. 3 of the
// 9x3 window's 27 samples): the sums of only 4 samples' products.
template <int kLanes>
inline void SampleChunk(const uint8_t* right, const LanczosTable& table, __m256 base, const float* offset,
                        const int32_t* row, int32_t row_shift, int valid, __m256* r, __m256* g) {
  static_assert(kLanes == 8 || kLanes == 4);
  static_assert(sizeof(LanczosTaps) == 64);
  const __m256 xr = _mm256_add_ps(base, _mm256_load_ps(offset));
  const __m256i i0 = _mm256_cvttps_epi32(xr);
  const __m256 frac = _mm256_sub_ps(xr, _mm256_cvtepi32_ps(i0));
  alignas(32) uint32_t col[8], entry_byte[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(col),
                     _mm256_add_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(row)),
                                      _mm256_add_epi32(i0, _mm256_set1_epi32(row_shift))));
  _mm256_store_si256(
      reinterpret_cast<__m256i*>(entry_byte),
      _mm256_slli_epi32(
          _mm256_cvttps_epi32(_mm256_fmadd_ps(frac, _mm256_set1_ps(float(kLanczosSteps)), _mm256_set1_ps(0.5f))), 6));
  const uint8_t* table_bytes = reinterpret_cast<const uint8_t*>(table.data());
  __m256 wp[kLanes], gp[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    if (k >= valid) {  // padding: no sample (the last chunk only)
      wp[k] = gp[k] = _mm256_setzero_ps();
      continue;
    }
    // Bytes i0-4 .. i0+3; the taps sit in lanes 2..7 (lanczos_taps.h).
    const __m256 p =
        _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(right + col[k] - 4))));
    const LanczosTaps& t = *reinterpret_cast<const LanczosTaps*>(table_bytes + entry_byte[k]);
    wp[k] = _mm256_mul_ps(_mm256_load_ps(t.w), p);
    gp[k] = _mm256_mul_ps(_mm256_load_ps(t.g), p);
  }
  if constexpr (kLanes == 8) {
    *r = TransposeSum8(wp), *g = TransposeSum8(gp);
  } else {
    *r = TransposeSum4(wp), *g = TransposeSum4(gp);
  }
}

// SubpixelWindow::FitPass of a window on the AVX2 path (is_vector()).
inline FitPassSums FitPassVector(const SubpixelWindow::VectorView& w, double d, float gain, float offset) {
  const __m256 base = _mm256_set1_ps(float(w.x - d));
  const __m256 vgain = _mm256_set1_ps(gain), voffset = _mm256_set1_ps(offset);
  const LanczosTable& table = *w.table;
  __m256 sgg = _mm256_setzero_ps(), sgr = sgg, sg = sgg, srr = sgg, sr = sgg, sge = sgg, sre = sgg, se = sgg, slr = sgg;
  auto accumulate = [&](__m256 r, __m256 g, __m256 e, __m256 l) {
    sgg = _mm256_fmadd_ps(g, g, sgg), sgr = _mm256_fmadd_ps(g, r, sgr), sg = _mm256_add_ps(sg, g);
    srr = _mm256_fmadd_ps(r, r, srr), sr = _mm256_add_ps(sr, r);
    sge = _mm256_fmadd_ps(g, e, sge), sre = _mm256_fmadd_ps(r, e, sre), se = _mm256_add_ps(se, e);
    slr = _mm256_fmadd_ps(l, r, slr);
  };
  int c = 0;
  for (; c + 8 <= w.n; c += 8) {
    __m256 r, g;
    SampleChunk<8>(w.right, table, base, w.offset + c, w.row + c, 0, 8, &r, &g);
    const __m256 l = _mm256_load_ps(w.l + c);
    accumulate(r, g, _mm256_sub_ps(_mm256_fnmadd_ps(vgain, r, l), voffset), l);
  }
  if (c < w.n) {  // the padded chunk: r, g are 0 in its padding lanes, e is masked there
    __m256 r, g;
    if (w.n - c <= 4) {
      SampleChunk<4>(w.right, table, base, w.offset + c, w.row + c, 0, w.n - c, &r, &g);
    } else {
      SampleChunk<8>(w.right, table, base, w.offset + c, w.row + c, 0, w.n - c, &r, &g);
    }
    const __m256 l = _mm256_load_ps(w.l + c);
    const __m256 e = _mm256_and_ps(_mm256_sub_ps(_mm256_fnmadd_ps(vgain, r, l), voffset), LeadingMask(w.n - c));
    accumulate(r, g, e, l);
  }
  const __m256 lanes[8] = {sgg, sgr, sg, srr, sr, sge, sre, se};
  alignas(32) float sums[8];
  _mm256_store_ps(sums, TransposeSum8(lanes));
  return FitPassSums{sums[0], sums[1], sums[2], sums[3], sums[4], sums[5], sums[6], sums[7], HorizontalSum(slr)};
}

}  // namespace
}  // namespace stereorig
