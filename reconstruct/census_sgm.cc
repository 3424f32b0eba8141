#include "reconstruct/census_sgm.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "calib/core/input_error.h"
#include "reconstruct/parallel_for.h"

namespace stereorig {

void SgmOptions::Check() const {
  if (p1 < 1 || p1 > 200) throw InputError("sgm.p1", "must be in [1, 200] census bits");
  if (p2 <= p1 || p2 > 1000) throw InputError("sgm.p2", "must be in (p1, 1000] census bits");
  if (num_paths != 3 && num_paths != 4) throw InputError("sgm.num_paths", "must be 3 or 4");
  if (uniqueness_percent < 0 || uniqueness_percent > 50)
    throw InputError("sgm.uniqueness_percent", "must be in [0, 50]");
  if (lr_max_diff_px < 0) throw InputError("sgm.lr_max_diff_px", "must be >= 0 (0 = exact)");
}

CensusImage CensusTransform(const cv::Mat& grey, int row_begin, int row_end, int num_threads, int half_width,
                            int half_height, int col_begin, int col_end) {
  STEREORIG_CHECK(half_width >= 1 && half_width <= 4 && half_height >= 1 && half_height <= 3);
  STEREORIG_CHECK(grey.type() == CV_8UC1);
  CensusImage out;
  out.width = grey.cols;
  out.height = grey.rows;
  out.bits.assign(size_t(grey.cols) * grey.rows, 0);
  row_begin = std::max(0, row_begin);
  row_end = std::min(grey.rows, row_end);
  const int w = grey.cols, h = grey.rows;
  const int c0 = std::clamp(col_begin, 0, w), c1 = std::clamp(col_end, c0, w);
  ParallelForChunks(row_end - row_begin, num_threads, [&](int b, int e) {
    std::vector<uint8_t> padded(w + 8);
    for (int y = row_begin + b; y < row_begin + e; ++y) {
      const uint8_t* centre = grey.ptr<uint8_t>(y);
      uint64_t* dst = out.bits.data() + size_t(y) * w;
      for (int dy = -half_height; dy <= half_height; ++dy) {
        const uint8_t* src = grey.ptr<uint8_t>(std::clamp(y + dy, 0, h - 1));
        // Replicated border in a padded copy keeps the inner loop branch-free.
        for (int i = 0; i < 4; ++i) {
          padded[i] = src[0];
          padded[w + 4 + i] = src[w - 1];
        }
        std::copy(src, src + w, padded.begin() + 4);
        for (int dx = -half_width; dx <= half_width; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const uint8_t* nb = padded.data() + 4 + dx;
          for (int x = c0; x < c1; ++x) dst[x] = (dst[x] << 1) | uint64_t(nb[x] < centre[x]);
        }
      }
    }
  });
  return out;
}

namespace {

constexpr uint16_t kBig = 0x3FFF;  // "impossible" path cost; + p1 cannot overflow

// One SGM recursion step along a path:
//   cur[d] = c[d] + min(prev[d], prev[d-1]+p1, prev[d+1]+p1, prev_min+p2) - prev_min.
// `prev` and `cur` point at element 0 of arrays padded with kBig at [-1] and
// [n]. Returns min_d cur[d].
inline uint16_t PathStep(const uint8_t* __restrict c, const uint16_t* __restrict prev, uint16_t prev_min,
                         uint16_t* __restrict cur, int n, uint16_t p1, uint16_t p2) {
  const uint16_t cap = uint16_t(prev_min + p2);
  uint16_t m = 0xFFFF;
  for (int d = 0; d < n; ++d) {
    const uint16_t a = std::min(prev[d], cap);
    const uint16_t b = std::min(uint16_t(prev[d - 1] + p1), uint16_t(prev[d + 1] + p1));
    const uint16_t r = uint16_t(c[d] + std::min(a, b) - prev_min);
    cur[d] = r;
    m = std::min(m, r);
  }
  return m;
}

inline uint16_t FirstStep(const uint8_t* __restrict c, uint16_t* __restrict cur, int n) {
  uint16_t m = 0xFFFF;
  for (int d = 0; d < n; ++d) {
    cur[d] = c[d];
    m = std::min(m, cur[d]);
  }
  return m;
}

inline void AddTo(uint16_t* __restrict s, const uint16_t* __restrict l, int n) {
  for (int d = 0; d < n; ++d) s[d] = uint16_t(s[d] + l[d]);
}

inline uint16_t MinOf(const uint16_t* __restrict v, int n) {
  uint16_t m = 0xFFFF;
  for (int i = 0; i < n; ++i) m = std::min(m, v[i]);
  return m;
}

// A (D+2)-element path buffer with kBig sentinels; data() points at element 0.
struct PathBuffer {
  explicit PathBuffer(int n) : v(n + 2, kBig) {}
  uint16_t* data() { return v.data() + 1; }
  std::vector<uint16_t> v;
};

}  // namespace

cv::Mat SgmMatch(const CensusImage& left, const CensusImage& right, const cv::Rect& region, int min_disparity,
                 int num_disparities, const SgmOptions& options) {
  STEREORIG_CHECK(region.width > 0 && region.height > 0 && num_disparities > 0);
  STEREORIG_CHECK(region.x >= 0 && region.y >= 0 && region.x + region.width <= left.width &&
                  region.y + region.height <= left.height);
  const int w = region.width, h = region.height, n = num_disparities;
  const int rw = right.width;
  const uint16_t p1 = uint16_t(options.p1), p2 = uint16_t(options.p2);

  // Cost volume (h, w, n), uint8. Disparities whose right pixel falls off the
  // image get the maximum cost, so they are never preferred.
  std::vector<uint8_t> cost(size_t(h) * w * n);
  for (int y = 0; y < h; ++y) {
    const uint64_t* cl = left.row(region.y + y);
    const uint64_t* cr = right.row(region.y + y);
    for (int x = 0; x < w; ++x) {
      uint8_t* c = cost.data() + (size_t(y) * w + x) * n;
      const uint64_t l = cl[region.x + x];
      const int xr0 = region.x + x - min_disparity;  // right x at d index 0
      // d indices whose right pixel xr0 - d lies in [0, rw): a branch-free run.
      const int d_lo = std::clamp(xr0 - rw + 1, 0, n), d_hi = std::clamp(xr0 + 1, d_lo, n);
      std::fill(c, c + d_lo, uint8_t(kCensusMaxCost));
      const uint64_t* r = cr + xr0;
      for (int d = d_lo; d < d_hi; ++d) c[d] = uint8_t(__builtin_popcountll(l ^ r[-d]));
      std::fill(c + d_hi, c + n, uint8_t(kCensusMaxCost));
    }
  }

  // Aggregated cost (h, w, n) when a second pass is needed; otherwise one row.
  const bool two_pass = options.num_paths == 4;
  std::vector<uint16_t> sum(size_t(two_pass ? h : 1) * w * n);
  std::vector<uint16_t> vert_prev(size_t(w) * (n + 2), kBig), vert_cur(size_t(w) * (n + 2), kBig);
  std::vector<uint16_t> vert_prev_min(w), vert_cur_min(w);
  PathBuffer ha(n), hb(n);

  cv::Mat disparity(h, w, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  std::vector<uint16_t> right_best(w + n);

  auto winner_take_all = [&](int y, const uint16_t* srow) {
    // Right-view best costs from the same volume: right pixel xr_local =
    // x - d + n - 1 (>= 0). A reversed contiguous run, so it vectorises.
    std::fill(right_best.begin(), right_best.end(), uint16_t(0xFFFF));
    for (int x = 0; x < w; ++x) {
      const uint16_t* s = srow + size_t(x) * n;
      uint16_t* rb = right_best.data() + x + n - 1;
      for (int d = 0; d < n; ++d) rb[-d] = std::min(rb[-d], s[d]);
    }
    float* out = disparity.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const uint16_t* s = srow + size_t(x) * n;
      const uint16_t best_cost = MinOf(s, n);
      const int best = int(std::find(s, s + n, best_cost) - s);
      if (best == 0 || best == n - 1) continue;  // at the range's edge: not a true minimum
      const uint16_t second = std::min(MinOf(s, best - 1), MinOf(s + best + 2, n - best - 2));
      if (int(second) * (100 - options.uniqueness_percent) < int(best_cost) * 100) continue;
      // Left-right check: the right pixel's own best disparity lies within
      // lr_max_diff_px of ours iff one of the left pixels x+k at disparity
      // best+k (|k| <= tolerance, same right pixel) reaches its best cost.
      const uint16_t right_min = right_best[x - best + n - 1];
      bool consistent = false;
      for (int k = -options.lr_max_diff_px; k <= options.lr_max_diff_px && !consistent; ++k) {
        const int xk = x + k, dk = best + k;
        if (xk >= 0 && xk < w && dk >= 0 && dk < n) consistent = srow[size_t(xk) * n + dk] <= right_min;
      }
      if (!consistent) continue;
      const double c0 = s[best - 1], c1 = s[best], c2 = s[best + 1];
      // Equiangular fit: two lines of equal and opposite slope through the
      // three costs; the steeper side fixes the slope.
      const double slope = std::max(c0, c2) - c1;
      const double delta = slope > 0 ? 0.5 * (c0 - c2) / slope : 0.0;
      out[x] = float(min_disparity + best + delta);
    }
  };

  // Forward pass: left->right, right->left, top->bottom.
  for (int y = 0; y < h; ++y) {
    uint16_t* srow = sum.data() + (two_pass ? size_t(y) * w * n : 0);
    const uint8_t* crow = cost.data() + size_t(y) * w * n;
    // Top -> bottom: column buffers, double-buffered across rows.
    for (int x = 0; x < w; ++x) {
      uint16_t* cur = vert_cur.data() + size_t(x) * (n + 2) + 1;
      const uint8_t* c = crow + size_t(x) * n;
      vert_cur_min[x] = y == 0
                            ? FirstStep(c, cur, n)
                            : PathStep(c, vert_prev.data() + size_t(x) * (n + 2) + 1, vert_prev_min[x], cur, n, p1, p2);
      std::copy(cur, cur + n, srow + size_t(x) * n);
    }
    std::swap(vert_prev, vert_cur);
    std::swap(vert_prev_min, vert_cur_min);
    // Left -> right.
    uint16_t m = FirstStep(crow, ha.data(), n);
    AddTo(srow, ha.data(), n);
    for (int x = 1; x < w; ++x) {
      m = PathStep(crow + size_t(x) * n, ha.data(), m, hb.data(), n, p1, p2);
      AddTo(srow + size_t(x) * n, hb.data(), n);
      std::swap(ha, hb);
    }
    // Right -> left.
    m = FirstStep(crow + size_t(w - 1) * n, ha.data(), n);
    AddTo(srow + size_t(w - 1) * n, ha.data(), n);
    for (int x = w - 2; x >= 0; --x) {
      m = PathStep(crow + size_t(x) * n, ha.data(), m, hb.data(), n, p1, p2);
      AddTo(srow + size_t(x) * n, hb.data(), n);
      std::swap(ha, hb);
    }
    if (!two_pass) winner_take_all(y, srow);
  }
  if (!two_pass) return disparity;

  // Backward pass: bottom -> top, then the winner per row.
  for (int y = h - 1; y >= 0; --y) {
    uint16_t* srow = sum.data() + size_t(y) * w * n;
    const uint8_t* crow = cost.data() + size_t(y) * w * n;
    for (int x = 0; x < w; ++x) {
      uint16_t* cur = vert_cur.data() + size_t(x) * (n + 2) + 1;
      const uint8_t* c = crow + size_t(x) * n;
      vert_cur_min[x] = y == h - 1
                            ? FirstStep(c, cur, n)
                            : PathStep(c, vert_prev.data() + size_t(x) * (n + 2) + 1, vert_prev_min[x], cur, n, p1, p2);
      AddTo(srow + size_t(x) * n, cur, n);
    }
    std::swap(vert_prev, vert_cur);
    std::swap(vert_prev_min, vert_cur_min);
    winner_take_all(y, srow);
  }
  return disparity;
}

}  // namespace stereorig
