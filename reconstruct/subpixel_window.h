// The window of one sub-pixel fit (subpixel_refine.h) and the sums its
// passes need: the Gauss-Newton sums of the Lanczos-sampled fit and the ZNCC
// of the linearly interpolated distinctness test (disparity_state.h).
//
// The fit samples the right row at x+u - d - gx*u - gy*v for each window
// pixel (u, v): the offsets -gx*u+u - gy*v do not change between passes or
// between the fit and its distinctness test, so the window holds them, with
// the left values and sums, once. The samples are flattened over the rows
// and taken 8 at a time with AVX2 (where compiled so, STEREORIG_NATIVE):
// each sample's 6 Lanczos taps are one 8-wide multiply (lanczos_taps.h),
// 8 samples' products are summed by one transposing reduction, and the sums
// are accumulated 8 samples per instruction. The portable path is the
// plain loop; the two agree up to float summation order
// (subpixel_window_test.cc).
#pragma once

#include <cstdint>
#include <memory>
#include <new>
#include <opencv2/core.hpp>
#include <type_traits>
#include <utility>

#include "reconstruct/lanczos_taps.h"
#include "reconstruct/subpixel_refine.h"

namespace stereorig {

// Window sums of one Gauss-Newton pass at disparity d with gain a and offset
// b: r the right sample, g its slope along x, l the left pixel and
// e = l - a r - b. The normal equations of (d, a, b) follow from these
// (RefineDisparity): J = (a g, -r, -1) per sample.
struct FitPassSums {
  double gg = 0, gr = 0, g = 0, rr = 0, r = 0;  // sums of g^2, g r, g, r^2, r
  double ge = 0, re = 0, e = 0;                 // sums of g e, r e, e
  double lr = 0;                                // sum of l r (the ZNCC)
};

enum class WindowKernel {
  kFastest,   // AVX2 where compiled and the window has at most kMaxVectorSamples samples
  kPortable,  // the plain loop (the reference for the AVX2 path's tests)
};

class SubpixelWindow {
 public:
  // The most samples the AVX2 path takes (larger windows: portable): up to
  // 9x13, which holds the line-index vernier's 9x9 (line_index.h).
  static constexpr int kMaxVectorSamples = 120;

  // Left pixel (x, y), the slopes dd/dx, dd/dy and the window size of o.
  // The window must lie inside the left image (the caller checks).
  SubpixelWindow(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x, double slope_y,
                 const SubpixelOptions& o, WindowKernel kernel = WindowKernel::kFastest);

  int size() const { return n_; }  // samples, (2 hw + 1)(2 hh + 1)
  // The AVX2 path's flattened samples, for a caller that inlines the pass
  // (subpixel_window_avx2.h). Valid while the window lives, on is_vector()
  // windows only.
  struct VectorView {
    const uint8_t* right;  // right.data
    const LanczosTable* table;
    int x, n;        // the window's centre column and its samples
    const float* l;  // the padded arrays below
    const float* offset;
    const int32_t* row;
  };
  bool is_vector() const { return vector_; }
  VectorView vector_view() const { return {right_.data, table_, x_, n_, l_, offset_, row_}; }
  WindowKernel kernel() const { return kernel_; }  // as constructed
  // Sums of the left values and their squares over the window (exact).
  int64_t left_sum() const { return lsum_; }
  int64_t left_sum2() const { return lsum2_; }

  // The sums of a pass at disparity d. Every sample's 6 Lanczos taps
  // i0-2 .. i0+3 must lie inside the right row, and for the AVX2 path also
  // i0-4 (the caller checks the reach; lanczos_taps.h).
  FitPassSums FitPass(double d, float gain, float offset) const;

  // Each sample's right value r[s] and slope g[s] (Lanczos) at disparity d,
  // from right rows shifted by row_shift (y + v + row_shift: those rows
  // must be inside the image), s < size(); r, g hold padded_size() floats.
  // The same reach as FitPass.
  void Sample(double d, int row_shift, float* r, float* g) const;
  int padded_size() const { return (n_ + 7) / 8 * 8; }

  // ZNCC of the window at disparity d, the right row linearly interpolated
  // (columns i0 .. i0+3 read: inside the row, the caller checks); -1 if
  // either window is flat.
  double Zncc(double d) const;
  // Zncc(d0) and Zncc(d1) into zncc[0], zncc[1] (the same values), in one
  // walk over the window: the distinctness test's two shifts.
  void ZnccPair(double d0, double d1, double zncc[2]) const;

 private:
  FitPassSums FitPassPortable(double d, float gain, float offset) const;
  void SamplePortable(double d, int row_shift, float* r, float* g) const;
  double ZnccPortable(double d) const;
  // Defined in AVX2 builds only (and called only there): declared in all so
  // the class is the same in every file.
  void SetUpLanes();  // the AVX2 path's arrays and the left sums
  FitPassSums FitPassAvx2(double d, float gain, float offset) const;
  void SampleAvx2(double d, int row_shift, float* r, float* g) const;
  double ZnccAvx2(double d) const;
  void ZnccPairAvx2(double d0, double d1, double zncc[2]) const;
  friend class WindowZnccProbe;

  const cv::Mat& left_;
  const cv::Mat& right_;
  int x_, y_, hw_, hh_, n_;
  float stride_;    // 1 - slope_x: right px per left px along the row
  double slope_y_;  // dd/dy
  WindowKernel kernel_;
  bool vector_;  // the AVX2 path
  int64_t lsum_ = 0, lsum2_ = 0;
  // AVX2 path, flattened samples padded to a multiple of 8 (padding: the
  // centre pixel's position with l = 0, masked out of the sums):
  alignas(32) float l_[kMaxVectorSamples];       // left values
  alignas(32) float offset_[kMaxVectorSamples];  // right column minus (x - d): u (1 - gx) - gy v
  alignas(32) int32_t row_[kMaxVectorSamples];   // byte offset of the right row from right.data
  const LanczosTable* table_ = nullptr;          // LanczosTapTable(), held so a pass need not look it up
};

// Room for one SubpixelWindow, set up or not: std::optional's role, without
// its cost here. GCC 12's std::optional zero-fills its storage when
// constructed, 1.5 KB for a window: ~200 instructions a pixel, 8 % of
// RefineAndAccept's (callgrind, cup). The window is trivially destructible,
// so nothing is run when the slot goes.
class WindowSlot {
 public:
  WindowSlot() {}  // storage left uninitialised
  WindowSlot(const WindowSlot&) = delete;
  WindowSlot& operator=(const WindowSlot&) = delete;
  template <class... Args>
  SubpixelWindow& emplace(Args&&... args) {
    window_ = std::construct_at(reinterpret_cast<SubpixelWindow*>(storage_), std::forward<Args>(args)...);
    return *window_;
  }
  bool has_value() const { return window_ != nullptr; }
  const SubpixelWindow& operator*() const { return *window_; }  // has_value() must hold
  const SubpixelWindow* operator->() const { return window_; }

 private:
  static_assert(std::is_trivially_destructible_v<SubpixelWindow>);
  alignas(SubpixelWindow) unsigned char storage_[sizeof(SubpixelWindow)];
  SubpixelWindow* window_ = nullptr;  // into storage_ once set up
};

// RefineDisparity (subpixel_refine.h), also handing back the window it
// fitted (left empty where it returned before setting one up), so that the
// distinctness test can reuse it (RefineAndAccept, disparity_state.h). The
// same result as RefineDisparity.
SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                               double slope_y, const SubpixelOptions& options, WindowSlot* window);

// WindowZncc (subpixel_refine.h) of one window at several disparities,
// the window set up once: the distinctness test (disparity_state.h) takes
// two.
class WindowZnccProbe {
 public:
  WindowZnccProbe(const cv::Mat& left, const cv::Mat& right, int x, int y, double slope_x, double slope_y,
                  const SubpixelOptions& o);
  // On a window already set up with WindowKernel::kFastest for these
  // slopes and options (the fit's: RefineDisparity above), which must
  // outlive the probe. The same values as the constructor above.
  WindowZnccProbe(const SubpixelWindow& window, double slope_x, double slope_y, const SubpixelOptions& o);
  WindowZnccProbe(const WindowZnccProbe&) = delete;
  WindowZnccProbe& operator=(const WindowZnccProbe&) = delete;
  // = WindowZncc(left, right, x, y, d, slope_x, slope_y, o): -1 where the
  // window leaves either image.
  double At(double d) const;
  // At(d0), At(d1) into zncc[0], zncc[1] (the same values), the window
  // walked once where both are inside.
  void AtPair(double d0, double d1, double zncc[2]) const;

 private:
  int x_, right_cols_;
  bool Inside(double d) const { return window_ && x_ - d - reach_px_ >= 0 && x_ - d + reach_px_ < right_cols_; }

  double reach_px_;                         // the right window's extent about x - d, with the taps' margin
  WindowSlot own_;                          // set up by the first constructor, if inside the left image
  const SubpixelWindow* window_ = nullptr;  // own_ or the caller's; null if the left window leaves the image
};

}  // namespace stereorig
