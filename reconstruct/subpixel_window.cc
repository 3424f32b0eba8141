#include "reconstruct/subpixel_window.h"

#include <cmath>

#include "calib/core/input_error.h"

#include "reconstruct/lanczos_taps.h"

#if defined(__AVX2__)
#include <immintrin.h>

#include "reconstruct/subpixel_window_avx2.h"
#endif

namespace stereorig {

SubpixelWindow::SubpixelWindow(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x, double slope_y,
                               const SubpixelOptions& o, WindowKernel kernel)
    : left_(left),
      right_(right),
      x_(x),
      y_(y),
      hw_(o.half_width_px),
      hh_(o.half_height_px),
      n_((2 * hw_ + 1) * (2 * hh_ + 1)),
      stride_(float(1.0 - slope_x)),
      slope_y_(slope_y),
      kernel_(kernel) {
#if defined(__AVX2__)
  vector_ = kernel == WindowKernel::kFastest && n_ <= kMaxVectorSamples;
  if (vector_) {
    SetUpLanes();
    return;
  }
#else
  vector_ = false;
#endif
  for (int v = -hh_; v <= hh_; ++v) {
    const uint8_t* lrow = left.ptr<uint8_t>(y + v) + x;
    for (int u = -hw_; u <= hw_; ++u) lsum_ += lrow[u], lsum2_ += lrow[u] * lrow[u];
  }
}

// The AVX2 pass inlined here, for the callers that do not inline it
// themselves (RefineDisparity does: subpixel_window_avx2.h).
[[gnu::flatten]] FitPassSums SubpixelWindow::FitPass(double d, float gain, float offset) const {
#if defined(__AVX2__)
  if (vector_) return FitPassAvx2(d, gain, offset);
#endif
  return FitPassPortable(d, gain, offset);
}

void SubpixelWindow::Sample(double d, int row_shift, float* r, float* g) const {
#if defined(__AVX2__)
  if (vector_) return SampleAvx2(d, row_shift, r, g);
#endif
  SamplePortable(d, row_shift, r, g);
}

double SubpixelWindow::Zncc(double d) const {
#if defined(__AVX2__)
  if (vector_) return ZnccAvx2(d);
#endif
  return ZnccPortable(d);
}

void SubpixelWindow::ZnccPair(double d0, double d1, double zncc[2]) const {
#if defined(__AVX2__)
  if (vector_) return ZnccPairAvx2(d0, d1, zncc);
#endif
  zncc[0] = ZnccPortable(d0), zncc[1] = ZnccPortable(d1);
}

FitPassSums SubpixelWindow::FitPassPortable(double d, float gain, float offset) const {
  const LanczosTable& table = LanczosTapTable();
  float sgg = 0, sgr = 0, sg = 0, srr = 0, sr = 0, sge = 0, sre = 0, se = 0, slr = 0;
  for (int v = -hh_; v <= hh_; ++v) {
    const uint8_t* lrow = left_.ptr<uint8_t>(y_ + v) + x_;
    const uint8_t* rrow = right_.ptr<uint8_t>(y_ + v);
    const float row_start = float(x_ - d - slope_y_ * v);
    for (int u = -hw_; u <= hw_; ++u) {
      float r, g;
      SampleLanczos(rrow, row_start + float(u) * stride_, table, &r, &g);
      const float l = lrow[u];
      const float e = l - gain * r - offset;
      sgg += g * g, sgr += g * r, sg += g;
      srr += r * r, sr += r;
      sge += g * e, sre += r * e, se += e;
      slr += l * r;
    }
  }
  return FitPassSums{sgg, sgr, sg, srr, sr, sge, sre, se, slr};
}

void SubpixelWindow::SamplePortable(double d, int row_shift, float* r, float* g) const {
  const LanczosTable& table = LanczosTapTable();
  int s = 0;
  for (int v = -hh_; v <= hh_; ++v) {
    const uint8_t* rrow = right_.ptr<uint8_t>(y_ + v + row_shift);
    const float row_start = float(x_ - d - slope_y_ * v);
    for (int u = -hw_; u <= hw_; ++u, ++s) SampleLanczos(rrow, row_start + float(u) * stride_, table, &r[s], &g[s]);
  }
  for (; s < padded_size(); ++s) r[s] = g[s] = 0;
}

double SubpixelWindow::ZnccPortable(double d) const {
  float rs = 0, rs2 = 0, lr = 0;
  for (int v = -hh_; v <= hh_; ++v) {
    const uint8_t* lrow = left_.ptr<uint8_t>(y_ + v) + x_;
    const uint8_t* rrow = right_.ptr<uint8_t>(y_ + v);
    const float row_start = float(x_ - d - slope_y_ * v);
    for (int u = -hw_; u <= hw_; ++u) {
      const float xr = row_start + float(u) * stride_;
      const int i0 = int(xr);
      const float t = xr - float(i0);
      const float r = (1 - t) * rrow[i0] + t * rrow[i0 + 1];
      rs += r, rs2 += r * r, lr += lrow[u] * r;
    }
  }
  const double n = n_, ls = double(lsum_) / n;
  const double lv = double(lsum2_) / n - ls * ls, rv = double(rs2) / n - double(rs / n) * (rs / n);
  if (!(lv > 0 && rv > 0)) return -1;
  return (lr / n - ls * (rs / n)) / std::sqrt(lv * rv);
}

namespace {

// The right window's extent about x - d, with the linear taps' margin.
double ZnccReachPx(double slope_x, double slope_y, const SubpixelOptions& o) {
  return o.half_width_px * (1 + std::abs(slope_x)) + std::abs(slope_y) * o.half_height_px + 4;
}

}  // namespace

WindowZnccProbe::WindowZnccProbe(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x,
                                 double slope_y, const SubpixelOptions& o)
    : x_(x), right_cols_(right.cols), reach_px_(ZnccReachPx(slope_x, slope_y, o)) {
  const int hw = o.half_width_px, hh = o.half_height_px;
  if (y - hh < 0 || y + hh >= left.rows || x - hw < 0 || x + hw >= left.cols) return;
  own_.emplace(left, right, x, y, slope_x, slope_y, o);
  window_ = &*own_;
}

WindowZnccProbe::WindowZnccProbe(const SubpixelWindow& window, double slope_x, double slope_y, const SubpixelOptions& o)
    : x_(window.x_), right_cols_(window.right_.cols), reach_px_(ZnccReachPx(slope_x, slope_y, o)), window_(&window) {
  STEREORIG_CHECK(window.kernel() == WindowKernel::kFastest);
}

double WindowZnccProbe::At(double d) const {
  if (!Inside(d)) return -1;
  return window_->Zncc(d);
}

void WindowZnccProbe::AtPair(double d0, double d1, double zncc[2]) const {
  if (Inside(d0) && Inside(d1)) return window_->ZnccPair(d0, d1, zncc);
  zncc[0] = At(d0), zncc[1] = At(d1);
}

#if defined(__AVX2__)
namespace {

// The window's shape flattened into lanes: each sample's u, v and byte
// offsets from the centre pixel in the left and right images. The same
// for every window of a run (options and image steps are fixed), so each
// thread keeps the last one.
struct WindowLanes {
  const LanczosTable* table = nullptr;  // LanczosTapTable(): here so a window need not look it up (a call, a guard)
  int hw = -1, hh = -1;
  size_t left_step = 0, right_step = 0;
  alignas(32) float u[SubpixelWindow::kMaxVectorSamples], v[SubpixelWindow::kMaxVectorSamples];
  alignas(32) int32_t left_offset[SubpixelWindow::kMaxVectorSamples], right_row[SubpixelWindow::kMaxVectorSamples];
};

// Fills *lanes for this shape. Out of line: inlined, its loops cost
// SetUpLanes's every call registers and stack it otherwise does not need.
[[gnu::noinline]] void BuildLanes(int hw, int hh, size_t left_step, size_t right_step, WindowLanes* lanes) {
  lanes->hw = hw, lanes->hh = hh, lanes->left_step = left_step, lanes->right_step = right_step;
  lanes->table = &LanczosTapTable();
  int s = 0;
  for (int v = -hh; v <= hh; ++v)
    for (int u = -hw; u <= hw; ++u, ++s) {
      lanes->u[s] = float(u), lanes->v[s] = float(v);
      lanes->left_offset[s] = int32_t(v * int64_t(left_step) + u);
      lanes->right_row[s] = int32_t(v * int64_t(right_step));
    }
  for (; s % 8 != 0; ++s) {  // padding: copies of the centre sample
    lanes->u[s] = lanes->v[s] = 0;
    lanes->left_offset[s] = lanes->right_row[s] = 0;
  }
}

const WindowLanes& LanesFor(int hw, int hh, size_t left_step, size_t right_step) {
  thread_local WindowLanes lanes;
  if (lanes.hw != hw || lanes.hh != hh || lanes.left_step != left_step || lanes.right_step != right_step)
    BuildLanes(hw, hh, left_step, right_step, &lanes);
  return lanes;
}

}  // namespace

void SubpixelWindow::SetUpLanes() {
  const WindowLanes& lanes = LanesFor(hw_, hh_, left_.step[0], right_.step[0]);
  table_ = lanes.table;
  const uint8_t* centre = left_.ptr<uint8_t>(y_) + x_;
  // A 4-byte gather reads up to 3 bytes past a sample: not past the last
  // row's end.
  const bool gather = y_ + hh_ < left_.rows - 1 || x_ + hw_ + 3 < left_.cols;
  const __m256 stride = _mm256_set1_ps(stride_), minus_gy = _mm256_set1_ps(float(-slope_y_));
  const __m256i right_centre = _mm256_set1_epi32(int32_t(y_ * right_.step[0])), low_byte = _mm256_set1_epi32(0xFF);
  __m256 ls = _mm256_setzero_ps(), ls2 = ls;
  const int n = n_;  // held: the stores below may alias n_ for the compiler, which then reloads it per chunk
  for (int c = 0; c < n; c += 8) {
    const __m256i left_offset = _mm256_load_si256(reinterpret_cast<const __m256i*>(lanes.left_offset + c));
    __m256 l;
    if (gather) {
      l = _mm256_cvtepi32_ps(
          _mm256_and_si256(_mm256_i32gather_epi32(reinterpret_cast<const int*>(centre), left_offset, 1), low_byte));
    } else {
      alignas(32) float values[8];
      for (int k = 0; k < 8; ++k) values[k] = centre[lanes.left_offset[c + k]];
      l = _mm256_load_ps(values);
    }
    if (c + 8 > n) l = _mm256_and_ps(l, LeadingMask(n - c));
    _mm256_store_ps(l_ + c, l);
    ls = _mm256_add_ps(ls, l), ls2 = _mm256_fmadd_ps(l, l, ls2);
    // u (1 - gx) - gy v: to float precision (~1e-6 px), as the positions.
    _mm256_store_ps(offset_ + c, _mm256_fmadd_ps(_mm256_load_ps(lanes.u + c), stride,
                                                 _mm256_mul_ps(_mm256_load_ps(lanes.v + c), minus_gy)));
    _mm256_store_si256(
        reinterpret_cast<__m256i*>(row_ + c),
        _mm256_add_epi32(right_centre, _mm256_load_si256(reinterpret_cast<const __m256i*>(lanes.right_row + c))));
  }
  // Integers below 2^24 (64 samples of at most 255^2): exact in float.
  lsum_ = int64_t(HorizontalSum(ls)), lsum2_ = int64_t(HorizontalSum(ls2));
}

FitPassSums SubpixelWindow::FitPassAvx2(double d, float gain, float offset) const {
  return FitPassVector(vector_view(), d, gain, offset);
}

void SubpixelWindow::SampleAvx2(double d, int row_shift, float* r, float* g) const {
  const __m256 base = _mm256_set1_ps(float(x_ - d));
  const int32_t shift = int32_t(row_shift * int64_t(right_.step[0]));
  const LanczosTable& table = *table_;
  for (int c = 0; c < n_; c += 8) {
    __m256 rc, gc;
    SampleChunk<8>(right_.data, table, base, offset_ + c, row_ + c, shift, 8, &rc, &gc);
    _mm256_storeu_ps(r + c, rc), _mm256_storeu_ps(g + c, gc);
  }
}

namespace {

// The linearly interpolated right values r of chunk c (8 samples from c;
// lanes past n are 0) at `base` = x - d, summed into rs, rs2 and lr (with
// the left values l).
inline void ZnccChunk(const uint8_t* right, __m256 base, const float* offset, const int32_t* row, const float* l,
                      int valid, __m256* rs, __m256* rs2, __m256* lr) {
  const __m256i low_byte = _mm256_set1_epi32(0xFF);
  const __m256 xr = _mm256_add_ps(base, _mm256_load_ps(offset));
  const __m256i i0 = _mm256_cvttps_epi32(xr);
  const __m256 t = _mm256_sub_ps(xr, _mm256_cvtepi32_ps(i0));
  // Bytes i0 .. i0+3 of each sample's row: i0 and i0+1 are the two taps.
  const __m256i col = _mm256_add_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(row)), i0);
  const __m256i q = _mm256_i32gather_epi32(reinterpret_cast<const int*>(right), col, 1);
  const __m256 p0 = _mm256_cvtepi32_ps(_mm256_and_si256(q, low_byte));
  const __m256 p1 = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(q, 8), low_byte));
  __m256 r = _mm256_fmadd_ps(t, _mm256_sub_ps(p1, p0), p0);
  if (valid < 8) r = _mm256_and_ps(r, LeadingMask(valid));
  *rs = _mm256_add_ps(*rs, r), *rs2 = _mm256_fmadd_ps(r, r, *rs2);
  *lr = _mm256_fmadd_ps(_mm256_load_ps(l), r, *lr);
}

// The ZNCC from the window's sums: n samples, the left sums (exact) and
// the right ones.
inline double ZnccOfSums(int samples, int64_t lsum, int64_t lsum2, __m256 rs, __m256 rs2, __m256 lr) {
  const double n = samples, ls = double(lsum) / n, mean_r = HorizontalSum(rs) / n;
  const double lv = double(lsum2) / n - ls * ls, rv = HorizontalSum(rs2) / n - mean_r * mean_r;
  if (!(lv > 0 && rv > 0)) return -1;
  return (HorizontalSum(lr) / n - ls * mean_r) / std::sqrt(lv * rv);
}

}  // namespace

double SubpixelWindow::ZnccAvx2(double d) const {
  const __m256 base = _mm256_set1_ps(float(x_ - d));
  __m256 rs = _mm256_setzero_ps(), rs2 = rs, lr = rs;
  for (int c = 0; c < n_; c += 8) ZnccChunk(right_.data, base, offset_ + c, row_ + c, l_ + c, n_ - c, &rs, &rs2, &lr);
  return ZnccOfSums(n_, lsum_, lsum2_, rs, rs2, lr);
}

void SubpixelWindow::ZnccPairAvx2(double d0, double d1, double zncc[2]) const {
  const __m256 base0 = _mm256_set1_ps(float(x_ - d0)), base1 = _mm256_set1_ps(float(x_ - d1));
  __m256 rs0 = _mm256_setzero_ps(), rs20 = rs0, lr0 = rs0, rs1 = rs0, rs21 = rs0, lr1 = rs0;
  for (int c = 0; c < n_; c += 8) {
    ZnccChunk(right_.data, base0, offset_ + c, row_ + c, l_ + c, n_ - c, &rs0, &rs20, &lr0);
    ZnccChunk(right_.data, base1, offset_ + c, row_ + c, l_ + c, n_ - c, &rs1, &rs21, &lr1);
  }
  zncc[0] = ZnccOfSums(n_, lsum_, lsum2_, rs0, rs20, lr0);
  zncc[1] = ZnccOfSums(n_, lsum_, lsum2_, rs1, rs21, lr1);
}
#endif  // __AVX2__

}  // namespace stereorig
