#include "reconstruct/local_surface_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/parallel_for.h"

namespace stereorig {

namespace {
// The windows' largest half size: filter2D stays direct (not DFT) below ~130
// taps, and the moments' sums in float stay exact enough.
constexpr int kMaxHalfSizePx = 30;
}  // namespace

void SurfaceFitOptions::Check() const {
  if (half_width_px < 2 || half_width_px > kMaxHalfSizePx)
    throw InputError("surface_fit_half_width_px", "must be in [2, " + std::to_string(kMaxHalfSizePx) + "]");
  if (half_height_px < 1 || half_height_px > kMaxHalfSizePx)
    throw InputError("surface_fit_half_height_px", "must be in [1, " + std::to_string(kMaxHalfSizePx) + "]");
  if (!(reference_misfit_px >= 0 && reference_misfit_px <= 10))
    throw InputError("surface_fit_reference_misfit_px", "must be in [0, 10] px (0 = the window never grows)");
  if (!(max_variance_growth >= 1 && max_variance_growth <= 100))
    throw InputError("surface_fit_max_variance_growth", "must be in [1, 100]");
  if (!(max_misfit_ratio >= 1 && max_misfit_ratio <= 100))
    throw InputError("surface_fit_max_misfit_ratio", "must be in [1, 100]");
}

namespace {

constexpr int kTerms = 6;  // the quadric's terms u^i v^j, in the order of its coefficients:
// the constant last. Then a Cholesky factor L of the normal matrix gives
// all the fit needs from the forward substitution z = L^-1 rhs alone: the
// fitted centre (the constant) z[5] / L[5][5], its predicted variance
// 1 / L[5][5]^2 and the fitted sum of squares c . rhs = |z|^2 (no back
// substitution, no second solve for the variance).
constexpr int kPowerU[kTerms] = {2, 1, 0, 1, 0, 0};
constexpr int kPowerV[kTerms] = {0, 1, 2, 0, 1, 0};
constexpr int kConstant = kTerms - 1;
using Matrix6 = std::array<std::array<double, kTerms>, kTerms>;

// The Cholesky factor L of a symmetric 6x6 matrix (lower triangle), with
// the reciprocals of its diagonal.
struct Factor6 {
  Matrix6 l{};
  std::array<double, kTerms> inv_diag{};
};

// Factors the symmetric a (lower triangle read): false if it is not
// positive definite. Written out at this fixed size (unrolled) rather than with Eigen::LLT, whose generic blocked code
// and L1 norm cost ~860 instructions per 6x6 factorisation and ~350 per pair of solves; on the demo cup two thirds of
// the fitted windows have holes and need their own (docs/reconstruct-log.md, "The refinement steps'
// instruction count").
inline bool Factor(const Matrix6& a, Factor6* f) {
#pragma GCC unroll 6
  for (int j = 0; j < kTerms; ++j) {
    double s = a[j][j];
#pragma GCC unroll 6
    for (int k = 0; k < j; ++k) s -= f->l[j][k] * f->l[j][k];
    if (!(s > 0)) return false;
    f->inv_diag[j] = 1 / std::sqrt(s);
#pragma GCC unroll 6
    for (int i = j + 1; i < kTerms; ++i) {
      double t = a[i][j];
#pragma GCC unroll 6
      for (int k = 0; k < j; ++k) t -= f->l[i][k] * f->l[j][k];
      f->l[i][j] = t * f->inv_diag[j];
    }
  }
  return true;
}

// The predicted variance of the fitted centre, relative to one pixel's
// (the constant's diagonal entry of the inverse normal matrix).
double CentreVariance(const Factor6& f) { return f.inv_diag[kConstant] * f.inv_diag[kConstant]; }

// The fitted centre (the constant term) and the fitted sum of squares
// c . rhs of the window whose normal matrix f factors.
inline void SolveCentre(const Factor6& f, const std::array<double, kTerms>& rhs, double* centre,
                        double* fitted_squares) {
  std::array<double, kTerms> z;
  double squares = 0;
#pragma GCC unroll 6
  for (int i = 0; i < kTerms; ++i) {
    double t = rhs[i];
#pragma GCC unroll 6
    for (int k = 0; k < i; ++k) t -= f.l[i][k] * z[k];
    z[i] = t * f.inv_diag[i];
    squares += z[i] * z[i];
  }
  *centre = z[kConstant] * f.inv_diag[kConstant];
  *fitted_squares = squares;
}

// The filter taps (x / half)^power, x = -half..half: offsets scaled to
// [-1, 1] so the 6x6 system is well conditioned in float.
cv::Mat PowerTaps(int half, int power, bool along_row) {
  cv::Mat k = along_row ? cv::Mat(1, 2 * half + 1, CV_32F) : cv::Mat(2 * half + 1, 1, CV_32F);
  for (int x = -half; x <= half; ++x) k.at<float>(x + half) = float(std::pow(double(x) / half, power));
  return k;
}

// Window sums of image * (u/hw)^i * (v/hh)^j: a row pass (shared by every j)
// then a column pass, with the taps of PowerTaps. Correlation (OpenCV does
// not flip kernels): out(x) = sum_u k(u) in(x + u); outside the image counts
// as 0.
cv::Mat RowMoment(const cv::Mat& image, const cv::Mat& taps) {
  cv::Mat out;
  cv::filter2D(image, out, CV_32F, taps, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
  return out;
}
// rows: the output rows wanted. Without BORDER_ISOLATED, filter2D reads the
// rows of `row_moment` around them as they are (0 only beyond its ends), so
// each output is the sum over the same pixels by the same arithmetic as when
// every row is filtered.
cv::Mat ColumnMoment(const cv::Mat& row_moment, const cv::Mat& taps, const cv::Range& rows) {
  cv::Mat out;
  cv::filter2D(row_moment.rowRange(rows), out, CV_32F, taps, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
  return out;
}

// The normal matrix of a window whose pixels are all valid (the same for
// every such window): sums of the terms' products over the window.
Matrix6 FullWindowMatrix(int hw, int hh) {
  Matrix6 a{};
  for (int v = -hh; v <= hh; ++v)
    for (int u = -hw; u <= hw; ++u)
      for (int p = 0; p < kTerms; ++p)
        for (int q = 0; q < kTerms; ++q)
          a[p][q] +=
              std::pow(double(u) / hw, kPowerU[p] + kPowerU[q]) * std::pow(double(v) / hh, kPowerV[p] + kPowerV[q]);
  return a;
}

// The fitted value at each pixel's centre and its window's RMS misfit (NaN
// = no fit), px; a pixel takes its fit where misfit <= max_misfit_px.
struct FitMaps {
  cv::Mat fitted, misfit;
  double median_misfit_px = 0;
  double max_misfit_px = 0;  // 0: nothing was fitted
};

// One pass of the fit with a (2 hw + 1) x (2 hh + 1) window over the ROI's
// valid mask and values (relative to their mean).
FitMaps FitQuadrics(const cv::Mat& mask, const cv::Mat& values, int hw, int hh, const SurfaceFitOptions& o,
                    int num_threads) {
  const cv::Size size = mask.size();
  Factor6 full_factor;
  STEREORIG_CHECK(Factor(FullWindowMatrix(hw, hh), &full_factor));
  const int full_count = (2 * hw + 1) * (2 * hh + 1);
  const double max_variance = o.max_variance_growth * CentreVariance(full_factor);
  // Per pixel: the fitted value at its centre and the RMS misfit (NaN = no fit).
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  cv::Mat fitted(size, CV_32F, cv::Scalar(kNaN)), misfit(size, CV_32F, cv::Scalar(kNaN));
  // Window sums: the mask's moments up to degree 4 (the normal matrix:
  // moment[i][j] = sum of mask (u/hw)^i (v/hh)^j), the values' up to degree
  // 2 (the right-hand side), and the values' squares (the misfit). In bands
  // of kBandRows output rows: the 22 moment images exist for one band at a
  // time (the row sums with its hh-row margins; over the whole ROI they were
  // 30 MB per module on the demo plate, live while the other module
  // matched). A row filter reads only its own row, and the column filters'
  // output rows have their whole window inside the band's input rows
  // (ColumnMoment), so every sum
  // comes from the same pixels by the same arithmetic as over the whole ROI
  // (filter2D stays direct, not DFT, below ~130 taps; Check() keeps the
  // half widths <= 30, so kernels have <= 61 taps).
  constexpr int kBandRows = 128;
  cv::Mat row_taps[5], column_taps[5];
  for (int i = 0; i <= 4; ++i) row_taps[i] = PowerTaps(hw, i, true), column_taps[i] = PowerTaps(hh, i, false);
  for (int y0 = 0; y0 < size.height; y0 += kBandRows) {
    const int y1 = std::min(size.height, y0 + kBandRows);
    const int in0 = std::max(0, y0 - hh), in1 = std::min(size.height, y1 + hh);  // the band's input rows
    const cv::Mat band_mask = mask.rowRange(in0, in1), band_values = values.rowRange(in0, in1);
    cv::Mat moment[5][5], value_moment[3][3];
    // Only the band's own rows of the column sums (not its margins).
    const cv::Range out_rows(y0 - in0, y1 - in0);
    cv::Mat squares;
    // Nine independent chains (a row filter, then its column filters), each
    // into its own images: on the pool (OpenCV's filter2D runs on one
    // thread), the same sums on any number of threads.
    ParallelForChunks(9, num_threads, [&](int begin, int end) {
      for (int chain = begin; chain < end; ++chain) {
        if (chain < 5) {  // the mask's moments, u^i
          const int i = chain;
          const cv::Mat row = RowMoment(band_mask, row_taps[i]);
          for (int j = 0; i + j <= 4; ++j) moment[i][j] = ColumnMoment(row, column_taps[j], out_rows);
        } else if (chain < 8) {  // the values', u^i
          const int i = chain - 5;
          const cv::Mat row = RowMoment(band_values, row_taps[i]);
          for (int j = 0; i + j <= 2; ++j) value_moment[i][j] = ColumnMoment(row, column_taps[j], out_rows);
        } else {  // the values' squares
          squares = ColumnMoment(RowMoment(band_values.mul(band_values), row_taps[0]), column_taps[0], out_rows);
        }
      }
    });
    ParallelForChunks(y1 - y0, num_threads, [&](int b, int e) {
      for (int y = y0 + b; y < y0 + e; ++y) {
        const float* valid = mask.ptr<float>(y);
        const float* m[5][5];
        const float* r[3][3];
        for (int i = 0; i <= 4; ++i)
          for (int j = 0; i + j <= 4; ++j) m[i][j] = moment[i][j].ptr<float>(y - y0);
        for (int i = 0; i <= 2; ++i)
          for (int j = 0; i + j <= 2; ++j) r[i][j] = value_moment[i][j].ptr<float>(y - y0);
        const float* sq = squares.ptr<float>(y - y0);
        float* fitted_row = fitted.ptr<float>(y);
        float* misfit_row = misfit.ptr<float>(y);
        for (int x = 0; x < size.width; ++x) {
          if (!(valid[x] > 0)) continue;
          const double n = m[0][0][x];
          if (n < 2 * kTerms) continue;
          std::array<double, kTerms> rhs;
          for (int p = 0; p < kTerms; ++p) rhs[p] = r[kPowerU[p]][kPowerV[p]][x];
          double centre, fit_sum;
          if (n > full_count - 0.5) {  // every pixel valid: the full window's system
            SolveCentre(full_factor, rhs, &centre, &fit_sum);
          } else {
            Matrix6 a;
            for (int p = 0; p < kTerms; ++p)
              for (int q = 0; q <= p; ++q) a[p][q] = m[kPowerU[p] + kPowerU[q]][kPowerV[p] + kPowerV[q]][x];
            Factor6 factor;
            if (!Factor(a, &factor)) continue;
            if (!(CentreVariance(factor) <= max_variance)) continue;
            SolveCentre(factor, rhs, &centre, &fit_sum);
          }
          fitted_row[x] = float(centre);
          misfit_row[x] = float(std::sqrt(std::max(0.0, sq[x] - fit_sum) / (n - kTerms)));
        }
      }
    });
  }
  FitMaps out{fitted, misfit, 0.0};
  std::vector<float> misfits;
  for (int y = 0; y < size.height; ++y) {
    const float* row = misfit.ptr<float>(y);
    for (int x = 0; x < size.width; ++x)
      if (std::isfinite(row[x])) misfits.push_back(row[x]);
  }
  if (misfits.empty()) return out;
  std::nth_element(misfits.begin(), misfits.begin() + misfits.size() / 2, misfits.end());
  // Never below 0.05 px (a fifth of the simulator's speckle scatter): on a
  // nearly noise-free surface the median misfit is rounding, and half the
  // windows would fail a gate of twice that.
  out.median_misfit_px = misfits[misfits.size() / 2];
  out.max_misfit_px = std::max(0.05, o.max_misfit_ratio * out.median_misfit_px);
  return out;
}

}  // namespace

int FitLocalSurface(const cv::Rect& roi_in, const SurfaceFitOptions& o, int num_threads, cv::Mat* disparity_px,
                    SurfaceFitSummary* summary) {
  SurfaceFitSummary own_summary;
  if (!summary) summary = &own_summary;
  *summary = SurfaceFitSummary{0, 0, o.half_width_px, o.half_height_px};
  const cv::Rect roi = roi_in & cv::Rect(0, 0, disparity_px->cols, disparity_px->rows);
  if (roi.area() == 0) return 0;
  cv::Mat d = (*disparity_px)(roi);
  // The valid mask, and the disparities relative to their mean (float sums).
  double sum = 0;
  int count = 0;
  for (int y = 0; y < roi.height; ++y) {
    const float* row = d.ptr<float>(y);
    for (int x = 0; x < roi.width; ++x)
      if (std::isfinite(row[x])) sum += row[x], ++count;
  }
  if (count == 0) return 0;
  const float mean = float(sum / count);
  cv::Mat mask(roi.size(), CV_32F, cv::Scalar(0)), values(roi.size(), CV_32F, cv::Scalar(0));
  for (int y = 0; y < roi.height; ++y) {
    const float* row = d.ptr<float>(y);
    float* valid = mask.ptr<float>(y);
    float* value = values.ptr<float>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (!std::isfinite(row[x])) continue;
      valid[x] = 1;
      value[x] = row[x] - mean;
    }
  }
  const FitMaps own = FitQuadrics(mask, values, o.half_width_px, o.half_height_px, o, num_threads);
  if (!(own.max_misfit_px > 0)) return 0;  // nothing fitted
  summary->median_misfit_px = own.median_misfit_px;
  // Stronger noise than the window was sized for: a second pass whose
  // window's sides grow with the square of the measured misfit's ratio to
  // the reference (both sides by one factor, capped so the longer stays
  // within kMaxHalfSizePx; the ratio alone, area with the variance, left the
  // speckle-0.4 scatter 1.2-1.5x the default's: local_surface_fit.h).
  // A pixel takes the wide fit only where its own window's fit is trusted
  // too (a seam or a wrong patch smaller than the wide window stays out of
  // it) and the wide one is (nearer a silhouette, or with a depth edge in
  // the larger window, it keeps its own window's fit).
  std::optional<FitMaps> wide;
  if (o.reference_misfit_px > 0 && own.median_misfit_px > o.reference_misfit_px) {
    const double ratio = own.median_misfit_px / o.reference_misfit_px;
    const double grow =
        std::min({ratio * ratio, double(kMaxHalfSizePx) / o.half_width_px, double(kMaxHalfSizePx) / o.half_height_px});
    const int hw = int(std::lround(o.half_width_px * grow)), hh = int(std::lround(o.half_height_px * grow));
    if (hw != o.half_width_px || hh != o.half_height_px) {
      wide = FitQuadrics(mask, values, hw, hh, o, num_threads);
      summary->half_width_px = hw, summary->half_height_px = hh;
    }
  }
  int replaced = 0;
  for (int y = 0; y < roi.height; ++y) {
    const float* own_misfit = own.misfit.ptr<float>(y);
    const float* own_fitted = own.fitted.ptr<float>(y);
    const float* wide_misfit = wide ? wide->misfit.ptr<float>(y) : nullptr;
    const float* wide_fitted = wide ? wide->fitted.ptr<float>(y) : nullptr;
    float* row = d.ptr<float>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (!(own_misfit[x] <= own.max_misfit_px)) continue;  // NaN: no fit
      row[x] = (wide && wide_misfit[x] <= wide->max_misfit_px ? wide_fitted[x] : own_fitted[x]) + mean;
      ++replaced;
    }
  }
  summary->replaced = replaced;
  return replaced;
}

}  // namespace stereorig
