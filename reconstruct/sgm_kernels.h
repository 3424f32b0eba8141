// The inner loops of census SGM (census_sgm.cc), twice: a portable scalar
// version over exactly n disparities, and an AVX2 version over n rounded up
// to a multiple of 16 lanes (census costs from nibble planes). Both give bit-identical disparities
// (census_sgm_test.cc checks it on random data): the padding lanes of every
// path cost are forced to kBig, so they never win a min and never feed a
// real lane: they equal the kBig sentinel the scalar path reads at [n].
//
// Layout, shared with census_sgm.cc: per pixel one contiguous run of
// `stride` disparities; path buffers have a kBig sentinel at [-1] and
// [stride].
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig::sgm {

inline constexpr uint16_t kBig = 0x3FFF;  // "impossible" path cost; 4 x kBig still fits uint16

// What a path step does with the sum of paths: start it (sum = v), add to
// the sum so far (sum = sum_in + v; sum_in may be sum itself, or the
// forward pass's sums when the backward pass writes a row's total apart),
// or nothing (kNone: the path alone, for its state; sum is not touched).
enum class SumMode { kStore, kAdd, kNone };

template <SumMode kMode>
inline uint16_t Accumulate(uint16_t* sum, const uint16_t* sum_in, uint16_t v) {
  if constexpr (kMode == SumMode::kNone) return v;
  return *sum = kMode == SumMode::kStore ? v : uint16_t(*sum_in + v);
}

struct ScalarKernels {
  using Path = uint16_t;                         // path costs (sums are uint16 in every kernel set)
  static constexpr Path kPathBig = kBig;         // path buffers' sentinels and padding lanes
  static constexpr bool kNibbleCosts = false;    // Cost reads the signatures themselves
  static constexpr bool kBlockUnrolled = false;  // one instance for any n (kBlocks is ignored)
  static int Stride(int n) { return n; }

  // c[d] = popcount(l ^ r[d]) for d in [lo, hi); the caller fills the rest.
  static void Cost(uint64_t l, const uint64_t* r, uint8_t* c, int lo, int hi, int /*stride*/) {
    for (int d = lo; d < hi; ++d) c[d] = uint8_t(__builtin_popcountll(l ^ r[d]));
  }

  // One SGM recursion step along a path:
  //   cur[d] = c[d] + min(prev[d], prev[d-1]+p1, prev[d+1]+p1, prev_min+p2) - prev_min,
  // accumulated into sum[d] (kMode). Returns min_d cur[d]; with kSumMin
  // also *sum_min = min_d sum[d] (the winner's cost, when this path is the
  // last).
  template <SumMode kMode, bool kSumMin = false, int kBlocks = 0>
  static uint16_t Step(const uint8_t* __restrict c, const uint16_t* __restrict prev, uint16_t prev_min,
                       uint16_t* __restrict cur, const uint16_t* sum_in, uint16_t* sum, int n, int /*stride*/,
                       uint16_t p1, uint16_t p2, uint16_t* sum_min = nullptr) {
    const uint16_t cap = uint16_t(prev_min + p2);
    uint16_t m = 0xFFFF, sm = 0xFFFF;
    for (int d = 0; d < n; ++d) {
      const uint16_t a = std::min(prev[d], cap);
      const uint16_t b = std::min(uint16_t(prev[d - 1] + p1), uint16_t(prev[d + 1] + p1));
      const uint16_t r = uint16_t(c[d] + std::min(a, b) - prev_min);
      cur[d] = r;
      sm = std::min(sm, Accumulate<kMode>(sum + d, sum_in + d, r));
      m = std::min(m, r);
    }
    if constexpr (kSumMin) *sum_min = sm;
    return m;
  }

  // The first pixel of a path: cur = c (sums and sum_min as Step).
  template <SumMode kMode, bool kSumMin = false, int kBlocks = 0>
  static uint16_t First(const uint8_t* __restrict c, uint16_t* __restrict cur, const uint16_t* sum_in, uint16_t* sum,
                        int n, int /*stride*/, uint16_t* sum_min = nullptr) {
    uint16_t m = 0xFFFF, sm = 0xFFFF;
    for (int d = 0; d < n; ++d) {
      cur[d] = c[d];
      sm = std::min(sm, Accumulate<kMode>(sum + d, sum_in + d, c[d]));
      m = std::min(m, cur[d]);
    }
    if constexpr (kSumMin) *sum_min = sm;
    return m;
  }

  // rb[d] = min(rb[d], s[d]) for d in [0, n).
  template <int kBlocks = 0>
  static void RightBest(const uint16_t* __restrict s, int n, int /*stride*/, uint16_t* rb) {
    for (int d = 0; d < n; ++d) rb[d] = std::min(rb[d], s[d]);
  }

  template <int kBlocks = 0>
  static uint16_t Min(const uint16_t* s, int n) {
    uint16_t m = 0xFFFF;
    for (int i = 0; i < n; ++i) m = std::min(m, s[i]);
    return m;
  }

  // The first index of the smallest cost m (m = Min(s, n)).
  static int FindFirst(const uint16_t* s, int n, int /*stride*/, uint16_t m) { return int(std::find(s, s + n, m) - s); }

  // The smallest cost off best-1..best+1 (0xFFFF if there is none).
  static uint16_t SecondBest(const uint16_t* s, int n, int /*stride*/, int best) {
    return std::min(Min(s, best - 1), Min(s + best + 2, n - best - 2));
  }
};

#if defined(__AVX2__)
// kXorPopcount[v][i] = popcount(i ^ v) for a nibble v and i in [0, 16),
// repeated in bytes 16..31 (both halves of a pshufb table).
struct XorPopcountTables {
  alignas(32) uint8_t bytes[16][32];
  constexpr XorPopcountTables() : bytes() {
    for (int v = 0; v < 16; ++v)
      for (int i = 0; i < 32; ++i) bytes[v][i] = uint8_t(__builtin_popcount(unsigned((i & 15) ^ v)));
  }
};
inline constexpr XorPopcountTables kXorPopcount{};

struct Avx2Kernels {
  // Census costs from nibble planes: a right row's signatures split into
  // 4-bit planes (plane k: nibble k of every signature, one byte each), so
  // one pshufb of the table popcount(i ^ left nibble k) by 32 bytes of plane
  // k counts that nibble's differing bits for 32 disparities, and byte adds
  // sum the planes: 2 instructions per nibble and 32 disparities (a 34-bit
  // 5x7 census has 9 nibbles) instead of the 64-bit popcount's ~3 per
  // disparity. Same counts as Cost, exactly.
  static constexpr bool kNibbleCosts = true;
  using Path = uint16_t;
  static constexpr Path kPathBig = kBig;
  // The block loops have instances for a fixed count of 16-lane blocks
  // (kBlocks), unrolled whole: a path step over 6 blocks then carries no
  // loop or remainder logic, which cost ~40% on top of its arithmetic.
  static constexpr bool kBlockUnrolled = true;
  static int Stride(int n) { return (n + 15) / 16 * 16; }

  // planes[k * plane_stride + j] = nibble k of sig[j] for j in [0, count),
  // k in [0, nibbles). 32 signatures at a time: each plane's nibbles are
  // masked in their 64-bit lanes, narrowed to bytes by three rounds of packs
  // (which interleave the 128-bit halves) and put back in order by one
  // permute and one shuffle; the rest one by one.
  static void NibblePlanes(const uint64_t* __restrict sig, int count, int nibbles, uint8_t* __restrict planes,
                           size_t plane_stride) {
    const __m256i low = _mm256_set1_epi64x(15);
    // After the packs and the permute, each 128-bit half holds signatures
    // 0,1,4,5,8,9,12,13, 2,3,6,7,10,11,14,15 (+16 in the upper half).
    const __m256i order = _mm256_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15,  //
                                           0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15);
    int j = 0;
    for (; j + 32 <= count; j += 32) {
      __m256i v[8];
      for (int i = 0; i < 8; ++i) v[i] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sig + j + 4 * i));
      for (int k = 0; k < nibbles; ++k) {
        const __m128i shift = _mm_cvtsi32_si128(4 * k);
        __m256i t[8];
        for (int i = 0; i < 8; ++i) t[i] = _mm256_and_si256(_mm256_srl_epi64(v[i], shift), low);
        const __m256i a = _mm256_packus_epi32(_mm256_packus_epi32(t[0], t[1]), _mm256_packus_epi32(t[2], t[3]));
        const __m256i b = _mm256_packus_epi32(_mm256_packus_epi32(t[4], t[5]), _mm256_packus_epi32(t[6], t[7]));
        const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(a, b), 0xD8);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(planes + k * plane_stride + j),
                            _mm256_shuffle_epi8(bytes, order));
      }
    }
    for (int k = 0; k < nibbles; ++k) {
      uint8_t* __restrict p = planes + k * plane_stride;
      const int shift = 4 * k;
      for (int i = j; i < count; ++i) p[i] = uint8_t((sig[i] >> shift) & 15);
    }
  }

  // c[d] = popcount(l ^ r[d]) for d in [0, stride), r[d]'s nibble k at
  // planes[k * plane_stride + d]; l has at most 4 * kNibbles bits.
  // kOddBlocks: stride is an odd multiple of 16; the last 16 lanes are then
  // read as 32 bytes (and 16 written): planes must be readable 16 bytes
  // beyond. Inlined into the caller's loop over a row (a call per pixel
  // spilled the tables).
  template <int kNibbles, bool kOddBlocks>
  [[gnu::always_inline]] static inline void CostFromNibbles(uint64_t l, const uint8_t* planes, size_t plane_stride,
                                                            uint8_t* c, int stride) {
    __m256i table[kNibbles];
    for (int k = 0; k < kNibbles; ++k)
      table[k] = _mm256_load_si256(reinterpret_cast<const __m256i*>(kXorPopcount.bytes[(l >> (4 * k)) & 15]));
    auto costs32 = [&](int d) {
      __m256i acc = _mm256_shuffle_epi8(table[0], _mm256_loadu_si256(reinterpret_cast<const __m256i*>(planes + d)));
      for (int k = 1; k < kNibbles; ++k)
        acc = _mm256_add_epi8(acc, _mm256_shuffle_epi8(table[k], _mm256_loadu_si256(reinterpret_cast<const __m256i*>(
                                                                     planes + size_t(k) * plane_stride + d))));
      return acc;
    };
    // The whole 32-lane chunks, then the odd 16 apart: no test per chunk.
    const int whole = kOddBlocks ? stride - 16 : stride;
    for (int d = 0; d < whole; d += 32) _mm256_storeu_si256(reinterpret_cast<__m256i*>(c + d), costs32(d));
    if constexpr (kOddBlocks)
      _mm_storeu_si128(reinterpret_cast<__m128i*>(c + whole), _mm256_castsi256_si128(costs32(whole)));
  }

  static __m256i Load(const uint16_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
  static void Store(uint16_t* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }

  static uint16_t HorizontalMin(__m256i v) {
    const __m128i m = _mm_min_epu16(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
    return uint16_t(_mm_cvtsi128_si32(_mm_minpos_epu16(m)));
  }

  // kBig in lanes >= k, 0 below: max() with it pins the padding lanes.
  static __m256i PadMask(int k) {
    const __m256i lane = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    return _mm256_and_si256(_mm256_cmpgt_epi16(lane, _mm256_set1_epi16(int16_t(k - 1))), _mm256_set1_epi16(kBig));
  }

  template <SumMode kMode>
  static __m256i Accumulate(uint16_t* sum, const uint16_t* sum_in, __m256i v) {
    if constexpr (kMode == SumMode::kNone) return v;
    const __m256i total = kMode == SumMode::kStore ? v : _mm256_add_epi16(Load(sum_in), v);
    Store(sum, total);
    return total;
  }

  // f(d) for d = 0, 16, ... below stride (kBlocks > 0: stride is 16 *
  // kBlocks, the loop unrolled whole; 0: known at run time only).
  template <int kBlocks, typename F>
  [[gnu::always_inline]] static inline void ForBlocks(int stride, F&& f) {
    if constexpr (kBlocks > 0) {
#pragma GCC unroll 16
      for (int b = 0; b < kBlocks; ++b) f(16 * b);
    } else {
#pragma GCC unroll 4
      for (int d = 0; d < stride; d += 16) f(d);
    }
  }

  // The last block's padding lanes (kBig in lanes >= n - (stride - 16), none
  // if n == stride); max() with it pins them.
  static __m256i LastPadMask(int n, int stride) { return PadMask(n - (stride - 16)); }

  // kBlocks: stride / 16 if the caller knows it at compile time, else 0.
  // The padding lanes' sums are kBig times the paths so far, above any real
  // sum: *sum_min is the real lanes' minimum, as in the scalar kernel.
  template <SumMode kMode, bool kSumMin = false, int kBlocks = 0>
  [[gnu::always_inline]] static inline uint16_t Step(const uint8_t* __restrict c, const uint16_t* __restrict prev,
                                                     uint16_t prev_min, uint16_t* __restrict cur,
                                                     const uint16_t* sum_in, uint16_t* sum, int n, int stride,
                                                     uint16_t p1, uint16_t p2, uint16_t* sum_min = nullptr) {
    if constexpr (kBlocks > 0) stride = 16 * kBlocks;
    const __m256i vp1 = _mm256_set1_epi16(int16_t(p1));
    const __m256i cap = _mm256_set1_epi16(int16_t(uint16_t(prev_min + p2)));
    const __m256i vprev_min = _mm256_set1_epi16(int16_t(prev_min));
    const __m256i pad = LastPadMask(n, stride);
    const int last = stride - 16;
    __m256i m = _mm256_set1_epi16(-1), sm = m;
    ForBlocks<kBlocks>(stride, [&](int d) {
      const __m256i cost = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c + d)));
      const __m256i a = _mm256_min_epu16(Load(prev + d), cap);
      const __m256i b =
          _mm256_min_epu16(_mm256_add_epi16(Load(prev + d - 1), vp1), _mm256_add_epi16(Load(prev + d + 1), vp1));
      __m256i r = _mm256_sub_epi16(_mm256_add_epi16(cost, _mm256_min_epu16(a, b)), vprev_min);
      if (d == last) r = _mm256_max_epu16(r, pad);
      Store(cur + d, r);
      const __m256i total = Accumulate<kMode>(sum + d, sum_in + d, r);
      if constexpr (kSumMin) sm = _mm256_min_epu16(sm, total);
      m = _mm256_min_epu16(m, r);
    });
    if constexpr (kSumMin) *sum_min = HorizontalMin(sm);
    return HorizontalMin(m);
  }

  template <SumMode kMode, bool kSumMin = false, int kBlocks = 0>
  [[gnu::always_inline]] static inline uint16_t First(const uint8_t* __restrict c, uint16_t* __restrict cur,
                                                      const uint16_t* sum_in, uint16_t* sum, int n, int stride,
                                                      uint16_t* sum_min = nullptr) {
    if constexpr (kBlocks > 0) stride = 16 * kBlocks;
    const __m256i pad = LastPadMask(n, stride);
    const int last = stride - 16;
    __m256i m = _mm256_set1_epi16(-1), sm = m;
    ForBlocks<kBlocks>(stride, [&](int d) {
      __m256i r = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c + d)));
      if (d == last) r = _mm256_max_epu16(r, pad);
      Store(cur + d, r);
      const __m256i total = Accumulate<kMode>(sum + d, sum_in + d, r);
      if constexpr (kSumMin) sm = _mm256_min_epu16(sm, total);
      m = _mm256_min_epu16(m, r);
    });
    if constexpr (kSumMin) *sum_min = HorizontalMin(sm);
    return HorizontalMin(m);
  }

  // rb[d] = min(rb[d], s[d]) over all lanes (padding lanes hold more than
  // any real sum, so they change nothing a real lane reads); rb must be
  // writable up to rb[stride - 1]. (The right view's best costs are stored
  // by decreasing right pixel, so a pixel's run of disparities is a forward
  // run there: no lane reversal, session 17.)
  template <int kBlocks = 0>
  static void RightBest(const uint16_t* __restrict s, int /*n*/, int stride, uint16_t* rb) {
    ForBlocks<kBlocks>(stride, [&](int d) { Store(rb + d, _mm256_min_epu16(Load(rb + d), Load(s + d))); });
  }

  template <int kBlocks = 0>
  static uint16_t Min(const uint16_t* s, int stride) {
    __m256i m = _mm256_set1_epi16(-1);
    ForBlocks<kBlocks>(stride, [&](int d) { m = _mm256_min_epu16(m, Load(s + d)); });
    return HorizontalMin(m);
  }

  // The first index of the smallest cost m (m = Min(s, stride)).
  static int FindFirst(const uint16_t* s, int /*n*/, int stride, uint16_t m) {
    const __m256i vm = _mm256_set1_epi16(int16_t(m));
    for (int d = 0; d < stride; d += 16) {
      const unsigned mask = unsigned(_mm256_movemask_epi8(_mm256_cmpeq_epi16(Load(s + d), vm)));
      if (mask) return d + __builtin_ctz(mask) / 2;
    }
    return 0;  // unreachable: m is one of the lanes
  }

  // best in [1, n-2]. The one or two blocks holding best-1..best+1 are
  // masked in registers (a scalar write then a vector read of the same
  // bytes would stall store forwarding): kNear, read from best-1's place,
  // has 0xFFFF in lanes best-1..best+1. The other blocks are plain minima.
  // With no lane left (n == 3) the padding's >= 3 kBig stands in for
  // 0xFFFF: both pass any uniqueness test (uniqueness_percent <= 50).
  static uint16_t SecondBest(const uint16_t* s, int /*n*/, int stride, int best) {
    static constexpr struct NearMask {
      uint16_t lanes[48];
      constexpr NearMask() : lanes() {
        for (int i = 16; i < 19; ++i) lanes[i] = 0xFFFF;
      }
    } kNear{};
    const int b0 = (best - 1) / 16 * 16, b1 = (best + 1) / 16 * 16;  // first lanes of those blocks
    __m256i m = _mm256_set1_epi16(-1);
    for (int d = 0; d < b0; d += 16) m = _mm256_min_epu16(m, Load(s + d));
    for (int d = b1 + 16; d < stride; d += 16) m = _mm256_min_epu16(m, Load(s + d));
    for (int d = b0; d <= b1; d += 16)  // kNear + 16 + d - (best - 1): lane l is near iff 0 <= d + l - best + 1 < 3
      m = _mm256_min_epu16(m, _mm256_or_si256(Load(s + d), Load(kNear.lanes + 16 + d - best + 1)));
    return HorizontalMin(m);
  }
};

// The path costs as bytes, 32 disparities per instruction instead of 16,
// where that gives the same path costs (SgmPathCostsFitBytes, census_sgm.h):
// every path cost is c + min(...) - prev_min with the min in [prev_min,
// prev_min + p2], so it lies in [0, max cost + p2], prev_min (a path cost)
// too, and the capped term prev_min + p2 is at most max cost + 2 p2 (a
// guided search's shifted predecessor can have its smallest cost outside
// the window, so its prev_min is not bounded by max cost). Below 255 that,
// unsigned saturating byte adds change no min a real lane takes (a
// saturated 255 loses to the capped term as the true value would), and the
// rest is exact: min - prev_min is in [0, p2] and adding the cost stays
// below 255. The sums stay
// uint16, in the same layout as Avx2Kernels' (costs, sums and the winner
// search are theirs); only the path buffers are bytes, with 255 as their
// sentinels and padding lanes (summed over 3-4 paths, 765-1020: above any
// real sum, <= 4 x (64 + 95), as the 16-bit kernels' multiples of kBig are).
// A stride that is an odd multiple of 16 ends in one 16-lane chunk.
struct Avx2ByteKernels : Avx2Kernels {
  using Path = uint8_t;
  static constexpr Path kPathBig = 0xFF;

  // 0xFF in byte lanes >= k (k in [1, 32]), 0 below.
  static __m256i BytePadMask(int k) {
    const __m256i lane = _mm256_setr_epi8(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21,
                                          22, 23, 24, 25, 26, 27, 28, 29, 30, 31);
    return _mm256_cmpgt_epi8(lane, _mm256_set1_epi8(char(k - 1)));
  }

  // The smallest byte of m and tail.
  static uint16_t ByteMin(__m256i m, __m128i tail) {
    __m128i x = _mm_min_epu8(_mm_min_epu8(_mm256_castsi256_si128(m), _mm256_extracti128_si256(m, 1)), tail);
    x = _mm_and_si128(_mm_min_epu8(x, _mm_srli_epi16(x, 8)), _mm_set1_epi16(0xFF));
    return uint16_t(_mm_cvtsi128_si32(_mm_minpos_epu16(x)));
  }

  // The 32 byte path costs r of lanes d..d+31 (or the low 16 of it, kHalf)
  // into the sums (kMode), their minimum into *sm (kSumMin).
  template <SumMode kMode, bool kSumMin, bool kHalf>
  [[gnu::always_inline]] static inline void AccumulateBytes(__m256i r, const uint16_t* sum_in, uint16_t* sum, int d,
                                                            __m256i* sm) {
    static_assert(!(kMode == SumMode::kNone && kSumMin), "the sums' minimum needs the sums");
    if constexpr (kMode != SumMode::kNone) {
      const __m256i lo = _mm256_cvtepu8_epi16(_mm256_castsi256_si128(r));
      const __m256i t0 = kMode == SumMode::kStore ? lo : _mm256_add_epi16(Load(sum_in + d), lo);
      Store(sum + d, t0);
      if constexpr (kSumMin) *sm = _mm256_min_epu16(*sm, t0);
      if constexpr (!kHalf) {
        const __m256i hi = _mm256_cvtepu8_epi16(_mm256_extracti128_si256(r, 1));
        const __m256i t1 = kMode == SumMode::kStore ? hi : _mm256_add_epi16(Load(sum_in + d + 16), hi);
        Store(sum + d + 16, t1);
        if constexpr (kSumMin) *sm = _mm256_min_epu16(*sm, t1);
      }
    }
  }

  // f(d, last) for the whole 32-lane chunks d = 0, 32, ... below stride
  // (kBlocks > 0: stride is 16 * kBlocks, unrolled whole); `last`: the
  // chunk holds lane n - 1 (no 16-lane chunk follows).
  template <int kBlocks, typename F>
  [[gnu::always_inline]] static inline void ForChunks(int stride, F&& f) {
    if constexpr (kBlocks > 0) {
#pragma GCC unroll 8
      for (int b = 0; b < kBlocks / 2; ++b) f(32 * b, kBlocks % 2 == 0 && b == kBlocks / 2 - 1);
    } else {
      const int whole = stride / 32 * 32;
#pragma GCC unroll 2
      for (int d = 0; d < whole; d += 32) f(d, stride % 32 == 0 && d == whole - 32);
    }
  }

  template <SumMode kMode, bool kSumMin = false, int kBlocks = 0>
  [[gnu::always_inline]] static inline uint16_t Step(const uint8_t* __restrict c, const uint8_t* __restrict prev,
                                                     uint16_t prev_min, uint8_t* __restrict cur, const uint16_t* sum_in,
                                                     uint16_t* sum, int n, int stride, uint16_t p1, uint16_t p2,
                                                     uint16_t* sum_min = nullptr) {
    if constexpr (kBlocks > 0) stride = 16 * kBlocks;
    const __m256i vp1 = _mm256_set1_epi8(char(p1));
    const __m256i cap = _mm256_set1_epi8(char(prev_min + p2));
    const __m256i vprev_min = _mm256_set1_epi8(char(prev_min));
    __m256i m = _mm256_set1_epi8(-1), sm = m;
    ForChunks<kBlocks>(stride, [&](int d, bool last) {
      const __m256i a = _mm256_min_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(prev + d)), cap);
      const __m256i b =
          _mm256_min_epu8(_mm256_adds_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(prev + d - 1)), vp1),
                          _mm256_adds_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(prev + d + 1)), vp1));
      __m256i r = _mm256_add_epi8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + d)),
                                  _mm256_sub_epi8(_mm256_min_epu8(a, b), vprev_min));
      if (last) r = _mm256_max_epu8(r, BytePadMask(n - (stride - 32)));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(cur + d), r);
      m = _mm256_min_epu8(m, r);
      AccumulateBytes<kMode, kSumMin, false>(r, sum_in, sum, d, &sm);
    });
    __m128i tail = _mm_set1_epi8(-1);
    if (stride % 32 == 16) {  // the last 16 lanes, in 128-bit registers
      const int d = stride - 16;
      const __m128i a =
          _mm_min_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(prev + d)), _mm256_castsi256_si128(cap));
      const __m128i b = _mm_min_epu8(
          _mm_adds_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(prev + d - 1)), _mm256_castsi256_si128(vp1)),
          _mm_adds_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(prev + d + 1)), _mm256_castsi256_si128(vp1)));
      __m128i r = _mm_add_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c + d)),
                               _mm_sub_epi8(_mm_min_epu8(a, b), _mm256_castsi256_si128(vprev_min)));
      r = _mm_max_epu8(r, _mm256_castsi256_si128(BytePadMask(n - d)));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(cur + d), r);
      tail = r;
      AccumulateBytes<kMode, kSumMin, true>(_mm256_castsi128_si256(r), sum_in, sum, d, &sm);
    }
    if constexpr (kSumMin) *sum_min = HorizontalMin(sm);
    return ByteMin(m, tail);
  }

  template <SumMode kMode, bool kSumMin = false, int kBlocks = 0>
  [[gnu::always_inline]] static inline uint16_t First(const uint8_t* __restrict c, uint8_t* __restrict cur,
                                                      const uint16_t* sum_in, uint16_t* sum, int n, int stride,
                                                      uint16_t* sum_min = nullptr) {
    if constexpr (kBlocks > 0) stride = 16 * kBlocks;
    __m256i m = _mm256_set1_epi8(-1), sm = m;
    ForChunks<kBlocks>(stride, [&](int d, bool last) {
      __m256i r = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + d));
      if (last) r = _mm256_max_epu8(r, BytePadMask(n - (stride - 32)));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(cur + d), r);
      m = _mm256_min_epu8(m, r);
      AccumulateBytes<kMode, kSumMin, false>(r, sum_in, sum, d, &sm);
    });
    __m128i tail = _mm_set1_epi8(-1);
    if (stride % 32 == 16) {
      const int d = stride - 16;
      const __m128i r = _mm_max_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c + d)),
                                     _mm256_castsi256_si128(BytePadMask(n - d)));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(cur + d), r);
      tail = r;
      AccumulateBytes<kMode, kSumMin, true>(_mm256_castsi128_si256(r), sum_in, sum, d, &sm);
    }
    if constexpr (kSumMin) *sum_min = HorizontalMin(sm);
    return ByteMin(m, tail);
  }
};
#endif  // __AVX2__

}  // namespace stereorig::sgm
