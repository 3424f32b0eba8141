#include "reconstruct/census_sgm.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "calib/core/input_error.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/sgm_kernels.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace stereorig {

void SgmOptions::Check() const {
  if (p1 < 1 || p1 > 200) throw InputError("sgm_p1", "must be in [1, 200] census bits");
  if (p2 <= p1 || p2 > 1000) throw InputError("sgm_p2", "must be in (sgm_p1, 1000] census bits");
  if (num_paths != 3 && num_paths != 4) throw InputError("sgm_paths", "must be 3 or 4");
  if (uniqueness_percent < 0 || uniqueness_percent > 50) throw InputError("uniqueness_percent", "must be in [0, 50]");
  if (lr_max_diff_px < 0) throw InputError("lr_max_diff_px", "must be >= 0 (0 = exact)");
  if (block_rows < 0) throw InputError("sgm.block_rows", "must be >= 0 (0 = about sqrt(rows))");
}

namespace {

#if defined(__AVX2__)
// Census of pixels [x, x + 32) of one row, 32 at a time: each neighbour's
// comparison sets one bit in one of 8 byte planes (plane j holds bits
// 8j..8j+7 of every pixel's signature), then the planes are transposed into
// 32 signatures. rows[i]: the padded copy (4 replicated px each side) of
// row dy = i - half_height. Bit positions are those of the scalar loop:
// the first neighbour in raster order is the highest bit. The window is a
// template argument so the loops unroll and the planes stay in registers.
template <int half_width, int half_height>
void Census32(const uint8_t* const* rows, int x, uint64_t* dst) {
  constexpr int count = (2 * half_width + 1) * (2 * half_height + 1) - 1;
  __m256i plane[8];
  for (__m256i& p : plane) p = _mm256_setzero_si256();
  const __m256i centre = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows[half_height] + 4 + x));
  int k = 0;
#pragma GCC unroll 8
  for (int dy = -half_height; dy <= half_height; ++dy)
#pragma GCC unroll 16
    for (int dx = -half_width; dx <= half_width; ++dx) {
      if (dx == 0 && dy == 0) continue;
      const int bit = count - 1 - k++;
      const __m256i nb = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows[dy + half_height] + 4 + x + dx));
      // nb < centre (unsigned) <=> max(nb, centre) != nb.
      const __m256i not_darker = _mm256_cmpeq_epi8(_mm256_max_epu8(nb, centre), nb);
      plane[bit >> 3] =
          _mm256_or_si256(plane[bit >> 3], _mm256_andnot_si256(not_darker, _mm256_set1_epi8(char(1 << (bit & 7)))));
    }
  // Byte transpose, within each 128-bit half (pixels 0-15 | 16-31).
  __m256i u[8], v[8];
  for (int j = 0; j < 4; ++j) {
    u[2 * j] = _mm256_unpacklo_epi8(plane[2 * j], plane[2 * j + 1]);      // px 0-7 | 16-23
    u[2 * j + 1] = _mm256_unpackhi_epi8(plane[2 * j], plane[2 * j + 1]);  // px 8-15 | 24-31
  }
  for (int j = 0; j < 2; ++j)
    for (int half = 0; half < 2; ++half) {
      const __m256i a = u[4 * j + half], b = u[4 * j + 2 + half];
      v[4 * j + 2 * half] = _mm256_unpacklo_epi16(a, b);      // 4 px of planes 4j..4j+3
      v[4 * j + 2 * half + 1] = _mm256_unpackhi_epi16(a, b);  // the next 4 px
    }
  // v[q] (q = 0..3): planes 0-3 of px 4q..4q+3 | 16+4q..; v[4 + q]: planes 4-7.
  for (int q = 0; q < 4; ++q) {
    const __m256i lo = _mm256_unpacklo_epi32(v[q], v[4 + q]);  // px 4q, 4q+1 | 16+4q, 17+4q
    const __m256i hi = _mm256_unpackhi_epi32(v[q], v[4 + q]);  // px 4q+2, 4q+3 | 18+4q, 19+4q
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst + x + 4 * q), _mm256_permute2x128_si256(lo, hi, 0x20));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst + x + 16 + 4 * q), _mm256_permute2x128_si256(lo, hi, 0x31));
  }
}

// Census32 for [x, end) in blocks of 32, the last one ending at `end` (it
// rewrites some pixels with the same signatures); end - x >= 32.
template <int half_width, int half_height>
void CensusRow32(const uint8_t* const* rows, int x, int end, uint64_t* dst) {
  for (; x + 32 <= end; x += 32) Census32<half_width, half_height>(rows, x, dst);
  if (x < end) Census32<half_width, half_height>(rows, end - 32, dst);
}

using CensusRowFn = void (*)(const uint8_t* const*, int, int, uint64_t*);
template <int half_width>
CensusRowFn CensusRowFor(int half_height) {
  switch (half_height) {
    case 1:
      return &CensusRow32<half_width, 1>;
    case 2:
      return &CensusRow32<half_width, 2>;
    default:
      return &CensusRow32<half_width, 3>;
  }
}
CensusRowFn CensusRowFor(int half_width, int half_height) {
  switch (half_width) {
    case 1:
      return CensusRowFor<1>(half_height);
    case 2:
      return CensusRowFor<2>(half_height);
    case 3:
      return CensusRowFor<3>(half_height);
    default:
      return CensusRowFor<4>(half_height);
  }
}
#endif

}  // namespace

CensusImage CensusTransform(const cv::Mat& grey, int row_begin, int row_end, int num_threads, int half_width,
                            int half_height, int col_begin, int col_end) {
  STEREORIG_CHECK(half_width >= 1 && half_width <= 4 && half_height >= 1 && half_height <= 3);
  STEREORIG_CHECK(grey.type() == CV_8UC1);
  CensusImage out;
  out.width = grey.cols;
  out.height = grey.rows;
  row_begin = std::clamp(row_begin, 0, grey.rows);
  row_end = std::clamp(row_end, row_begin, grey.rows);
  out.row_begin = row_begin;
  out.signature_bits = (2 * half_width + 1) * (2 * half_height + 1) - 1;
  out.bits.assign(size_t(grey.cols) * (row_end - row_begin), 0);
  const int w = grey.cols, h = grey.rows;
  const int c0 = std::clamp(col_begin, 0, w), c1 = std::clamp(col_end, c0, w);
  const int window_rows = 2 * half_height + 1;
#if defined(__AVX2__)
  const CensusRowFn census_row = CensusRowFor(half_width, half_height);
#endif
  ParallelForChunks(row_end - row_begin, num_threads, [&](int b, int e) {
    // The window's rows, each with a replicated border of 4 px either side
    // (keeps the inner loops branch-free).
    std::vector<uint8_t> padded(size_t(window_rows) * (w + 8));
    const uint8_t* rows[7];
    for (int y = row_begin + b; y < row_begin + e; ++y) {
      for (int i = 0; i < window_rows; ++i) {
        const uint8_t* src = grey.ptr<uint8_t>(std::clamp(y + i - half_height, 0, h - 1));
        uint8_t* row = padded.data() + size_t(i) * (w + 8);
        for (int j = 0; j < 4; ++j) {
          row[j] = src[0];
          row[w + 4 + j] = src[w - 1];
        }
        std::copy(src, src + w, row + 4);
        rows[i] = row;
      }
      uint64_t* dst = out.bits.data() + size_t(y - row_begin) * w;
      int x = c0;
#if defined(__AVX2__)
      if (c1 - c0 >= 32) {
        census_row(rows, c0, c1, dst);
        x = c1;
      }
#endif
      const uint8_t* centre = rows[half_height] + 4;
      for (; x < c1; ++x) {
        uint64_t bits = 0;
        for (int dy = -half_height; dy <= half_height; ++dy)
          for (int dx = -half_width; dx <= half_width; ++dx)
            if (dx != 0 || dy != 0) bits = (bits << 1) | uint64_t(rows[dy + half_height][4 + x + dx] < centre[x]);
        dst[x] = bits;
      }
    }
  });
  return out;
}

bool SgmPathCostsFitBytes(const SgmOptions& options, int signature_bits, int num_disparities) {
  const int max_cost = std::max(kCensusMaxCost, signature_bits);
  return num_disparities > 3 && max_cost + 2 * options.p2 <= 254;
}

bool SgmSimdAvailable() {
#if defined(__AVX2__)
  return true;
#else
  return false;
#endif
}

namespace {

using sgm::kBig;
using sgm::SumMode;

// The buffers of one SgmMatch call, allocated once per call (the band pass
// and the full-resolution pass are separate calls). All are a few rows: the
// costs are one row (computed again where needed, session 11), and the
// 4-path forward sums one block of rows, run again from the top->bottom
// path's saved state (session 15; they were the whole region, h x w x
// stride uint16 on fresh huge pages, ~40-50 MB a module).
template <typename P>  // the path costs' type (K::Path)
struct SgmWorkspace {
  std::vector<uint8_t> cost_row;     // (w, stride) + 63 to align: one row's matching costs
  std::vector<uint16_t> total_row;   // (w, stride): backward pass
  std::vector<uint16_t> block_sums;  // (block rows, w * stride rounded up to 32) + 31 to align: a block's forward sums
  std::vector<uint8_t> block_costs;  // (block rows, w * stride rounded up to 64) + 63 to align: its costs
  std::vector<P> saved_paths;        // (blocks - 1, w, stride + 2): the top->bottom path at blocks 1, 2, ...
  std::vector<uint16_t> saved_mins;  // (blocks - 1, w)
  std::vector<P> back_a, back_b;     // (w, stride + 2): bottom->top path, previous and current row
  std::vector<uint16_t> back_min_a, back_min_b;
  std::vector<P> vert_a, vert_b;  // (w, stride + 2): top->bottom path, previous and current row
  std::vector<uint16_t> vert_min_a, vert_min_b;
  std::vector<P> horiz_a, horiz_b, horiz_c, horiz_d;  // (stride + 2): left->right, right->left
  std::vector<P> shifted, shifted_rl;                 // (stride + 2): a predecessor in another window
  std::vector<uint16_t> right_best;                   // (16 + w + n)
  std::vector<uint16_t> row_min;                      // (w): each pixel's smallest total
  std::vector<uint64_t> right_reversed;               // (stride + right width + stride + 16)
  std::vector<uint8_t> nibble_planes;                 // (nibbles, right_reversed's size)
};

// Room for n elements (contents unspecified).
template <typename T>
T* Grow(std::vector<T>& v, size_t n) {
  if (v.size() < n) v.resize(n);
  return v.data();
}

// p rounded up to a 64-byte boundary (the caller allocated 63 bytes more).
template <typename T>
T* Align64(T* p) {
  return reinterpret_cast<T*>((reinterpret_cast<uintptr_t>(p) + 63) & ~uintptr_t(63));
}

// Path buffers for `count` pixels of `stride` lanes with `big` sentinels
// (K::kPathBig) at [-1] and [stride]; returns element 0 of pixel 0 (pixel i
// at i*(stride+2)).
template <typename P>
P* PathBuffers(std::vector<P>& v, int count, int stride, P big) {
  P* p = Grow(v, size_t(count) * (stride + 2));
  for (int i = 0; i < count; ++i) {
    p[size_t(i) * (stride + 2)] = big;
    p[size_t(i) * (stride + 2) + stride + 1] = big;
  }
  return p + 1;
}

// The path costs `prev` of a neighbour whose window starts `shift`
// disparities below the current pixel's, read in the current pixel's
// disparities: buf[i] = prev[i + shift] for i in [0, n), `big` (the kernel
// set's kPathBig) where i + shift falls outside the neighbour's n
// disparities (it never searched them: "no match there"), and `big` at [-1]
// and [n, stride] as in any path buffer. shift == 0 returns prev itself.
// (The copy is out of line and the test inline: it runs once per pixel and
// path, and only the guided search ever shifts.)
template <typename P, P kBigP>
[[gnu::noinline]] const P* ShiftedCopy(const P* prev, int shift, int n, int stride, P* buf) {
  std::fill(buf - 1, buf + stride + 1, kBigP);
  const int i0 = std::max(0, -shift), i1 = std::min(n, n - shift);
  if (i0 < i1) std::copy(prev + i0 + shift, prev + i1 + shift, buf + i0);
  return buf;
}
template <typename K>
inline const typename K::Path* InWindowOf(const typename K::Path* prev, int shift, int n, int stride,
                                          typename K::Path* buf) {
  return shift == 0 ? prev : ShiftedCopy<typename K::Path, K::kPathBig>(prev, shift, n, stride, buf);
}

// One row of matching costs: pixel x of the region (left signatures cl,
// window lo[x]) gets c[d] = Hamming(cl, right pixel region.x + x - lo[x] -
// d), kCensusMaxCost where that pixel is off the right image. The right row
// is given reversed (with `stride` padding each side) so that each pixel's
// run of disparities reads it forwards: as signatures (kNibbles == 0) or as
// kNibbles nibble planes of plane_stride bytes (sgm_kernels.h).
struct CostRowArgs {
  const uint64_t* cl;        // the left row's signatures
  const int16_t* lo;         // (w) the windows' first disparities
  const uint64_t* reversed;  // the right row reversed
  const uint8_t* planes;     // its nibble planes, or null
  size_t plane_stride;
  int region_x, w, n, stride, rw;
};
template <typename K, int kNibbles, bool kOddBlocks>
void CostRow(const CostRowArgs& args, uint8_t* cost_row) {
  const CostRowArgs a = args;  // a copy: the byte stores below might alias `args`, forcing reloads
  for (int x = 0; x < a.w; ++x) {
    uint8_t* c = cost_row + size_t(x) * a.stride;
    const int xr0 = a.region_x + x - a.lo[x];  // right x at d index 0
    // d indices whose right pixel xr0 - d lies in [0, rw).
    const int d_lo = std::clamp(xr0 - a.rw + 1, 0, a.n), d_hi = std::clamp(xr0 + 1, d_lo, a.n);
    if (d_lo == d_hi) {
      std::memset(c, kCensusMaxCost, size_t(a.stride));
      continue;
    }
    const size_t r0 = size_t(a.stride + a.rw - 1 - xr0);  // the reversed row's index of d index 0
    if constexpr (kNibbles > 0)
      K::template CostFromNibbles<kNibbles, kOddBlocks>(a.cl[a.region_x + x], a.planes + r0, a.plane_stride, c,
                                                        a.stride);
    else
      K::Cost(a.cl[a.region_x + x], a.reversed + r0, c, d_lo, d_hi, a.stride);
    // memset, not std::fill: GCC left the fill a byte loop.
    if (d_lo > 0) std::memset(c, kCensusMaxCost, size_t(d_lo));
    if (d_hi < a.n) std::memset(c + d_hi, kCensusMaxCost, size_t(a.n - d_hi));
  }
}

using CostRowFn = void (*)(const CostRowArgs&, uint8_t*);
template <typename K, bool kOddBlocks, int... k>
CostRowFn CostRowFor(int nibbles, std::integer_sequence<int, k...>) {
  static constexpr CostRowFn fns[] = {&CostRow<K, k + 1, kOddBlocks>...};
  return fns[std::clamp(nibbles, 1, 16) - 1];
}
// CostRow for signatures of `nibbles` nibbles and `stride` lanes: kernels
// with kNibbleCosts read nibble planes (one instance per count, 1..16, and
// per parity of stride / 16), others the signatures.
template <typename K>
CostRowFn CostRowFor(int nibbles, int stride) {
  if constexpr (K::kNibbleCosts) {
    if (stride % 32 != 0) return CostRowFor<K, true>(nibbles, std::make_integer_sequence<int, 16>());
    return CostRowFor<K, false>(nibbles, std::make_integer_sequence<int, 16>());
  } else {
    return &CostRow<K, 0, false>;
  }
}

// The sizes and penalties shared by one SGM call's row passes.
struct PathShape {
  int w = 0;       // pixels in a row of the region
  int n = 0;       // disparities per pixel (its window)
  int stride = 0;  // lanes per pixel in the cost row and the sums (K::Stride(n))
  uint16_t p1 = 0, p2 = 0;
  bool windows_vary = false;  // false: every pixel's window starts at the same disparity (SgmMatch)
};

// One row of the vertical path (top->bottom or bottom->top): path costs
// `cur` (w, stride + 2) and their minima cur_min from the row before along
// the path (prev, prev_min; lo_prev its windows, null for the first row),
// accumulated (kMode) from sin into srow; with kSumMin, sum_min[x] = the
// smallest of srow's costs of pixel x. A function of its own (not inlined
// into the caller's loop over rows): its loop keeps its pointers in
// registers.
template <typename K, int kBlocks, SumMode kMode, bool kSumMin>
[[gnu::noinline]] void VerticalRow(const PathShape& shape, const uint8_t* crow, const int16_t* lo,
                                   const int16_t* lo_prev, const uint16_t* sin, uint16_t* srow,
                                   const typename K::Path* prev, const uint16_t* prev_min, typename K::Path* cur,
                                   uint16_t* cur_min, typename K::Path* shifted, uint16_t* sum_min) {
  const int n = shape.n, stride = shape.stride;
  const bool vary = shape.windows_vary;
  const uint16_t p1 = shape.p1, p2 = shape.p2;  // locals: the row's stores might alias `shape`
  const size_t path_stride = size_t(stride) + 2;
  for (int x = 0; x < shape.w; ++x) {
    const size_t xs = size_t(x) * stride;
    uint16_t* smin = kSumMin ? sum_min + x : nullptr;
    cur_min[x] =
        lo_prev == nullptr
            ? K::template First<kMode, kSumMin, kBlocks>(crow + xs, cur + x * path_stride, sin + xs, srow + xs, n,
                                                         stride, smin)
            : K::template Step<kMode, kSumMin, kBlocks>(
                  crow + xs, InWindowOf<K>(prev + x * path_stride, vary ? lo[x] - lo_prev[x] : 0, n, stride, shifted),
                  prev_min[x], cur + x * path_stride, sin + xs, srow + xs, n, stride, p1, p2, smin);
  }
}

// Left->right and right->left along one row, added into srow, interleaved:
// each step waits for the previous pixel's minimum, so two independent
// chains keep the core busy. (Sums are modulo 2^16 additions: their order
// does not change them.) ha..hd, shifted, shifted_rl: path buffers of one
// pixel (PathBuffers).
template <typename K, int kBlocks>
[[gnu::noinline]] void HorizontalRow(const PathShape& shape, const uint8_t* crow, const int16_t* lo, uint16_t* srow,
                                     typename K::Path* ha, typename K::Path* hb, typename K::Path* hc,
                                     typename K::Path* hd, typename K::Path* shifted, typename K::Path* shifted_rl) {
  const int w = shape.w, n = shape.n, stride = shape.stride;
  const bool vary = shape.windows_vary;
  const uint16_t p1 = shape.p1, p2 = shape.p2;
  const size_t last = size_t(w - 1) * stride;
  uint16_t m_lr = K::template First<SumMode::kAdd, false, kBlocks>(crow, ha, srow, srow, n, stride);
  uint16_t m_rl =
      K::template First<SumMode::kAdd, false, kBlocks>(crow + last, hc, srow + last, srow + last, n, stride);
  for (int i = 1; i < w; ++i) {
    const int il = i, ir = w - 1 - i;
    const size_t xl = size_t(il) * stride, xr = size_t(ir) * stride;
    m_lr = K::template Step<SumMode::kAdd, false, kBlocks>(
        crow + xl, InWindowOf<K>(ha, vary ? lo[il] - lo[il - 1] : 0, n, stride, shifted), m_lr, hb, srow + xl,
        srow + xl, n, stride, p1, p2);
    m_rl = K::template Step<SumMode::kAdd, false, kBlocks>(
        crow + xr, InWindowOf<K>(hc, vary ? lo[ir] - lo[ir + 1] : 0, n, stride, shifted_rl), m_rl, hd, srow + xr,
        srow + xr, n, stride, p1, p2);
    std::swap(ha, hb);
    std::swap(hc, hd);
  }
}

// The winners of one row of summed costs srow (w, stride), windows lo:
// out[x] = the disparity refined by an equiangular fit, left NaN where the
// best cost is at the window's edge, fails the uniqueness test or the
// left-right check. row_min: each pixel's smallest sum if the last path
// found it (VerticalRow's sum_min), else null. right_best (right_best_size):
// scratch for the right view's best costs, right pixel x - lo - d (local)
// at [rb_origin - (x - lo - d)]: by decreasing right pixel, so pixel x's
// disparities 0, 1, ... are a forward run from [rb_origin - (x - lo)].
template <typename K, int kBlocks>
[[gnu::noinline]] void WinnerRow(const PathShape& shape, const uint16_t* srow, const int16_t* lo,
                                 const uint16_t* row_min, uint16_t* right_best, size_t right_best_size, int rb_origin,
                                 const SgmOptions& options, float* out) {
  const int w = shape.w, n = shape.n, stride = shape.stride;
  const int lr_max_diff_px = options.lr_max_diff_px, unique_percent = 100 - options.uniqueness_percent;
  std::fill(right_best, right_best + right_best_size, uint16_t(0xFFFF));
  // Pixels 16 apart in turn: neighbours' runs overlap shifted by one lane,
  // and a load overlapping the previous store stalls store forwarding.
  for (int phase = 0; phase < 16; ++phase)
    for (int x = phase; x < w; x += 16)
      K::template RightBest<kBlocks>(srow + size_t(x) * stride, n, stride, right_best + rb_origin - (x - lo[x]));
  for (int x = 0; x < w; ++x) {
    const uint16_t* s = srow + size_t(x) * stride;
    const uint16_t best_cost = row_min != nullptr ? row_min[x] : K::template Min<kBlocks>(s, stride);
    const int best = K::FindFirst(s, n, stride, best_cost);
    if (best == 0 || best == n - 1) continue;  // at the window's edge: not a true minimum
    const uint16_t second = K::SecondBest(s, n, stride, best);
    if (int(second) * unique_percent < int(best_cost) * 100) continue;
    // Left-right check: the right pixel's own best disparity lies within
    // lr_max_diff_px of ours iff one of the left pixels x+k at disparity
    // D+k (|k| <= tolerance, same right pixel) reaches its best cost. k = 0
    // first, without a load: s[best] is best_cost (right_min <= it).
    const int disparity_px = lo[x] + best;
    const uint16_t right_min = right_best[rb_origin - (x - disparity_px)];
    auto reaches = [&](int k) {
      const int xk = x + k, dk = disparity_px + k - lo[std::clamp(xk, 0, w - 1)];
      return xk >= 0 && xk < w && dk >= 0 && dk < n && srow[size_t(xk) * stride + dk] <= right_min;
    };
    bool consistent = best_cost <= right_min;
    for (int k = 1; k <= lr_max_diff_px && !consistent; ++k) consistent = reaches(-k) || reaches(k);
    if (!consistent) continue;
    const double c0 = s[best - 1], c1 = s[best], c2 = s[best + 1];
    // Equiangular fit: two lines of equal and opposite slope through the
    // three costs; the steeper side fixes the slope.
    const double slope = std::max(c0, c2) - c1;
    const double delta = slope > 0 ? 0.5 * (c0 - c2) / slope : 0.0;
    out[x] = float(disparity_px + delta);
  }
}

// The row passes of one SGM call, instances for its count of 16-lane blocks
// (K::kBlockUnrolled) up to kMaxUnrolledBlocks (n <= 256), else the
// run-time loops.
inline constexpr int kMaxUnrolledBlocks = 16;
template <typename K>
struct RowPasses {
  decltype(&VerticalRow<K, 0, SumMode::kStore, false>) forward_vertical;
  decltype(&VerticalRow<K, 0, SumMode::kNone, false>) vertical_alone;   // the path's state only, no sums
  decltype(&VerticalRow<K, 0, SumMode::kAdd, true>) backward_vertical;  // finds each pixel's smallest total
  decltype(&HorizontalRow<K, 0>) horizontal;
  decltype(&WinnerRow<K, 0>) winner;
};
template <typename K, int kBlocks>
constexpr RowPasses<K> RowPassesOf() {
  return {&VerticalRow<K, kBlocks, SumMode::kStore, false>, &VerticalRow<K, kBlocks, SumMode::kNone, false>,
          &VerticalRow<K, kBlocks, SumMode::kAdd, true>, &HorizontalRow<K, kBlocks>, &WinnerRow<K, kBlocks>};
}
template <typename K, int... k>
RowPasses<K> RowPassesFor(int blocks, std::integer_sequence<int, k...>) {
  static constexpr RowPasses<K> table[] = {RowPassesOf<K, k>()...};
  return table[blocks];
}
template <typename K>
RowPasses<K> RowPassesFor(int stride) {
  if constexpr (K::kBlockUnrolled) {
    const int blocks = stride / 16;
    return RowPassesFor<K>(blocks <= kMaxUnrolledBlocks ? blocks : 0,
                           std::make_integer_sequence<int, kMaxUnrolledBlocks + 1>());
  } else {
    return RowPassesOf<K, 0>();
  }
}

// SGM with per-pixel search windows: pixel (x, y) of `region` searches the
// n disparities [lo(y, x), lo(y, x) + n) (window_lo: CV_16SC1 of
// region.size()). Every path step reads its predecessor through
// InWindowOf, so the recursion compares equal disparities even where the
// windows of neighbours differ; with a constant lo it is plain SGM.
template <typename K>
cv::Mat SgmMatchWith(const CensusImage& left, const CensusImage& right, const cv::Rect& region,
                     const cv::Mat& window_lo, int n, const SgmOptions& options) {
  const int w = region.width, h = region.height;
  const int stride = K::Stride(n);
  const int rw = right.width;
  double lo_min = 0, lo_max = 0;
  cv::minMaxLoc(window_lo, &lo_min, &lo_max);
  const PathShape shape{w, n, stride, uint16_t(options.p1), uint16_t(options.p2), lo_min != lo_max};
  auto lo_row = [&](int y) { return window_lo.ptr<int16_t>(y); };
  using P = typename K::Path;
  constexpr P kPathBig = K::kPathBig;
  SgmWorkspace<P> ws;

  // The matching costs (w, stride), uint8 (CostRow), a row at a time,
  // never a volume (h x w x stride bytes: 21-25 MB a module at full
  // resolution on the demo; the census costs are cheap to recompute): one
  // row for the 3-path pass and the 4-path top->bottom pass, a block's rows
  // for the 4-path backward pass (below).
  // On a 64-byte boundary (32-byte stores then never straddle a cache line;
  // no kernel reads past w * stride).
  uint8_t* cost = Align64(Grow(ws.cost_row, size_t(w) * stride + 63));
  const size_t reversed_size = size_t(rw) + 2 * stride + 16;
  uint64_t* reversed = Grow(ws.right_reversed, reversed_size);
  std::fill(reversed, reversed + reversed_size, 0);
  // Kernels that read nibble planes get the reversed row split into them
  // (+32 bytes: CostFromNibbles may read 16 beyond the last plane).
  const int nibbles = (std::max(left.signature_bits, right.signature_bits) + 3) / 4;
  uint8_t* planes = K::kNibbleCosts ? Grow(ws.nibble_planes, size_t(nibbles) * reversed_size + 32) : nullptr;
  const CostRowFn cost_row = CostRowFor<K>(nibbles, stride);
  // The reversed row's indices CostRow reads: pixel x starts at
  // stride + rw - 1 - (region.x + x - lo[x]) and reads stride (+16) lanes;
  // only these get planes (about half the row at full resolution).
  const size_t planes_begin = size_t(std::clamp(stride + rw - region.x - w + int(lo_min), 0, int(reversed_size)));
  const size_t planes_end =
      size_t(std::clamp(2 * stride + rw + 15 - region.x + int(lo_max), int(planes_begin), int(reversed_size)));
  auto costs_of_row = [&](int y, uint8_t* dst) {
    const uint64_t* cr = right.row(region.y + y);
    std::reverse_copy(cr, cr + rw, reversed + stride);
    if constexpr (K::kNibbleCosts)
      K::NibblePlanes(reversed + planes_begin, int(planes_end - planes_begin), nibbles, planes + planes_begin,
                      reversed_size);
    cost_row(
        CostRowArgs{left.row(region.y + y), lo_row(y), reversed, planes, reversed_size, region.x, w, n, stride, rw},
        dst);
  };

  // One row of sums when a single pass suffices (num_paths 3); the
  // 4-path SGM's forward sums are held a block of rows at a time (below).
  const bool two_pass = options.num_paths == 4;
  P* vert_prev = PathBuffers(ws.vert_a, w, stride, kPathBig);
  P* vert_cur = PathBuffers(ws.vert_b, w, stride, kPathBig);
  uint16_t* vert_prev_min = Grow(ws.vert_min_a, w);
  uint16_t* vert_cur_min = Grow(ws.vert_min_b, w);
  P* ha = PathBuffers(ws.horiz_a, 1, stride, kPathBig);
  P* hb = PathBuffers(ws.horiz_b, 1, stride, kPathBig);
  P* hc = PathBuffers(ws.horiz_c, 1, stride, kPathBig);
  P* hd = PathBuffers(ws.horiz_d, 1, stride, kPathBig);
  P* shifted = PathBuffers(ws.shifted, 1, stride, kPathBig);
  P* shifted_rl = PathBuffers(ws.shifted_rl, 1, stride, kPathBig);
  uint16_t* row_min = Grow(ws.row_min, w);
  // Right-view best costs: the right pixel x - lo - d (local) is stored at
  // [rb_origin - (x - lo - d)], from 0 (x = w - 1, lo = lo_min, d = 0) up to
  // w - 1 + lo_max - lo_min + stride - 1 (the SIMD kernel writes all `stride`
  // lanes of a run).
  const int rb_origin = w - 1 - int(lo_min);
  const size_t right_best_size = size_t(w) + size_t(lo_max - lo_min) + 2 * size_t(stride);
  uint16_t* right_best = Grow(ws.right_best, right_best_size);

  cv::Mat disparity(h, w, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  const RowPasses<K> rows = RowPassesFor<K>(stride);
  const size_t row_elems = size_t(w) * stride;         // one row of costs or sums
  const size_t path_elems = size_t(w) * (stride + 2);  // one row of a path, with its sentinels

  // The top->bottom path's step to row y (costs crow), continued from the
  // state in vert_prev: into srow by `vertical` (forward_vertical stores
  // it, vertical_alone leaves srow alone).
  auto top_down = [&](decltype(rows.forward_vertical) vertical, int y, const uint8_t* crow, uint16_t* srow) {
    vertical(shape, crow, lo_row(y), y == 0 ? nullptr : lo_row(y - 1), srow, srow, vert_prev, vert_prev_min, vert_cur,
             vert_cur_min, shifted, nullptr);
    std::swap(vert_prev, vert_cur);
    std::swap(vert_prev_min, vert_cur_min);
  };
  // The forward paths of row y (top->bottom, then left->right and
  // right->left) summed into srow; costs into crow.
  auto forward_row = [&](int y, uint8_t* crow, uint16_t* srow) {
    costs_of_row(y, crow);
    top_down(rows.forward_vertical, y, crow, srow);
    rows.horizontal(shape, crow, lo_row(y), srow, ha, hb, hc, hd, shifted, shifted_rl);
  };
  if (!two_pass) {
    uint16_t* srow = Align64(Grow(ws.block_sums, row_elems + 31));
    for (int y = 0; y < h; ++y) {
      forward_row(y, cost, srow);
      rows.winner(shape, srow, lo_row(y), nullptr, right_best, right_best_size, rb_origin, options,
                  disparity.ptr<float>(y));
    }
    return disparity;
  }

  // 4 paths: the bottom->top path needs every row's forward sums, which
  // are not kept for the whole region (h x w x stride uint16: ~40-50 MB a
  // module at full resolution, fresh pages the kernel zeroes on every
  // call). The top->bottom path runs once alone, saving its state at the
  // start of each block of ~sqrt(h) rows; the backward pass then takes
  // the blocks bottom to top, runs the forward paths again over the block
  // from its saved state (keeping the block's costs and sums, a few MB in
  // cache) and goes up through it. Same arithmetic in the same order, so
  // the same sums; one more top->bottom path per row is the price.
  const int block_rows =
      std::min(h, options.block_rows > 0 ? options.block_rows : std::max(1, int(std::lround(std::sqrt(double(h))))));
  const int num_blocks = (h + block_rows - 1) / block_rows;
  // The state at the start of blocks 1, 2, ... (block 0 starts the path).
  P* saved = Grow(ws.saved_paths, size_t(num_blocks - 1) * path_elems);
  uint16_t* saved_min = Grow(ws.saved_mins, size_t(num_blocks - 1) * w);
  uint16_t* total = Grow(ws.total_row, row_elems);  // also the (untouched) sum row of vertical_alone
  for (int y = 0; y < h; ++y) {
    if (y % block_rows == 0 && y > 0) {
      const size_t slot = size_t(y / block_rows - 1);
      std::copy(vert_prev - 1, vert_prev - 1 + path_elems, saved + slot * path_elems);
      std::copy(vert_prev_min, vert_prev_min + w, saved_min + slot * w);
    }
    costs_of_row(y, cost);
    top_down(rows.vertical_alone, y, cost, total);
  }

  // Backward pass: bottom -> top, then the winner per row. The row's total
  // (forward sums + this path) goes to a row of its own, so the block's
  // sums are only read; the path step also finds each pixel's smallest
  // total (the winner's cost).
  // Each row of sums on a 64-byte boundary too (32 uint16).
  const size_t sum_pitch = (row_elems + 31) / 32 * 32;
  uint16_t* sums = Align64(Grow(ws.block_sums, size_t(block_rows) * sum_pitch + 31));
  // Each row of costs on a 64-byte boundary, as the single row is.
  const size_t cost_pitch = (row_elems + 63) / 64 * 64;
  uint8_t* costs = Align64(Grow(ws.block_costs, size_t(block_rows) * cost_pitch + 63));
  P* back_prev = PathBuffers(ws.back_a, w, stride, kPathBig);
  P* back_cur = PathBuffers(ws.back_b, w, stride, kPathBig);
  uint16_t* back_prev_min = Grow(ws.back_min_a, w);
  uint16_t* back_cur_min = Grow(ws.back_min_b, w);
  for (int b = num_blocks - 1; b >= 0; --b) {
    const int y0 = b * block_rows, y1 = std::min(h, y0 + block_rows);
    if (b > 0) {
      const size_t slot = size_t(b - 1);
      std::copy(saved + slot * path_elems, saved + (slot + 1) * path_elems, vert_prev - 1);
      std::copy(saved_min + slot * w, saved_min + (slot + 1) * w, vert_prev_min);
    }
    for (int y = y0; y < y1; ++y) forward_row(y, costs + (y - y0) * cost_pitch, sums + (y - y0) * sum_pitch);
    for (int y = y1 - 1; y >= y0; --y) {
      const uint8_t* crow = costs + (y - y0) * cost_pitch;
      rows.backward_vertical(shape, crow, lo_row(y), y == h - 1 ? nullptr : lo_row(y + 1), sums + (y - y0) * sum_pitch,
                             total, back_prev, back_prev_min, back_cur, back_cur_min, shifted, row_min);
      std::swap(back_prev, back_cur);
      std::swap(back_prev_min, back_cur_min);
      rows.winner(shape, total, lo_row(y), row_min, right_best, right_best_size, rb_origin, options,
                  disparity.ptr<float>(y));
    }
  }
  return disparity;
}

cv::Mat SgmMatchWindowed(const CensusImage& left, const CensusImage& right, const cv::Rect& region,
                         const cv::Mat& window_lo, int n, const SgmOptions& options) {
  STEREORIG_CHECK(region.width > 0 && region.height > 0 && n > 0);
  STEREORIG_CHECK(region.x >= 0 && region.y >= 0 && region.x + region.width <= left.width &&
                  region.y + region.height <= left.height);
  STEREORIG_CHECK(window_lo.type() == CV_16SC1 && window_lo.size() == region.size());
#if defined(__AVX2__)
  if (options.simd) {
    if (SgmPathCostsFitBytes(options, std::max(left.signature_bits, right.signature_bits), n))
      return SgmMatchWith<sgm::Avx2ByteKernels>(left, right, region, window_lo, n, options);
    return SgmMatchWith<sgm::Avx2Kernels>(left, right, region, window_lo, n, options);
  }
#endif
  return SgmMatchWith<sgm::ScalarKernels>(left, right, region, window_lo, n, options);
}

}  // namespace

cv::Mat SgmMatch(const CensusImage& left, const CensusImage& right, const cv::Rect& region, int min_disparity,
                 int num_disparities, const SgmOptions& options) {
  const cv::Mat window_lo(region.size(), CV_16SC1, cv::Scalar(min_disparity));
  return SgmMatchWindowed(left, right, region, window_lo, num_disparities, options);
}

cv::Mat SgmMatchGuided(const CensusImage& left, const CensusImage& right, const cv::Rect& region,
                       const cv::Mat& guide_px, int radius_px, int min_disparity, int num_disparities,
                       const SgmOptions& options) {
  STEREORIG_CHECK(guide_px.type() == CV_16SC1 && guide_px.size() == region.size() && radius_px >= 1);
  const int n = 2 * radius_px + 1;
  if (n >= num_disparities) return SgmMatch(left, right, region, min_disparity, num_disparities, options);
  cv::Mat window_lo(region.size(), CV_16SC1);
  for (int y = 0; y < region.height; ++y) {
    const int16_t* g = guide_px.ptr<int16_t>(y);
    int16_t* lo = window_lo.ptr<int16_t>(y);
    for (int x = 0; x < region.width; ++x)
      lo[x] = int16_t(std::clamp(g[x] - radius_px, min_disparity, min_disparity + num_disparities - n));
  }
  return SgmMatchWindowed(left, right, region, window_lo, n, options);
}

}  // namespace stereorig
