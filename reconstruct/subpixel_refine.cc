#include "reconstruct/subpixel_refine.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "calib/core/input_error.h"
#include "reconstruct/subpixel_window.h"
#if defined(__AVX2__)
#include "reconstruct/subpixel_window_avx2.h"  // the pass inlined into the Gauss-Newton loop
#endif

namespace stereorig {

void SubpixelOptions::Check() const {
  if (half_width_px < 1 || half_width_px > 30) throw InputError("subpixel_half_width_px", "must be in [1, 30]");
  if (half_height_px < 0 || half_height_px > 30) throw InputError("subpixel_half_height_px", "must be in [0, 30]");
  if (max_iterations < 1 || max_iterations > 50) throw InputError("subpixel.max_iterations", "must be in [1, 50]");
  if (!(converged_step_px > 0 && converged_step_px < 0.5))
    throw InputError("subpixel.converged_step_px", "must be in (0, 0.5) px");
  if (!(max_shift_px > 0 && max_shift_px <= 4)) throw InputError("subpixel.max_shift_px", "must be in (0, 4] px");
}

namespace {

// x = A^-1 b for the symmetric 3x3 A = [a00 a01 a02; a01 a11 a12; a02 a12
// a22], by cofactors (as Eigen's 3x3 inverse): not finite if A is singular.
// *inverse00: (A^-1)[0][0], the same as the first entry of the solution for
// b = (1, 0, 0) (no second solve for the variance of d).
void SolveSymmetric3(double a00, double a01, double a02, double a11, double a12, double a22, const double b[3],
                     double x[3], double* inverse00) {
  const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
  const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
  const double inv_det = 1.0 / (a00 * c00 + a01 * c01 + a02 * c02);
  x[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) * inv_det;
  x[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) * inv_det;
  x[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) * inv_det;
  *inverse00 = c00 * inv_det;
}

}  // namespace

SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                               double slope_y, const SubpixelOptions& o) {
  WindowSlot window;
  return RefineDisparity(left, right, x, y, start_px, slope_x, slope_y, o, &window);
}

SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                               double slope_y, const SubpixelOptions& o, WindowSlot* window_out) {
  SubpixelResult result;
  const int hw = o.half_width_px, hh = o.half_height_px;
  if (y - hh < 0 || y + hh >= left.rows || x - hw < 0 || x + hw >= left.cols) return result;
  // The sampled right columns must stay inside the image (6 taps).
  const double reach = hw + std::abs(slope_x) * hw + std::abs(slope_y) * hh + o.max_shift_px + 4;
  if (x - start_px - reach < 0 || x - start_px + reach >= right.cols) return result;
  // The AVX2 sums read 2 columns more to the left (subpixel_window.h); a
  // column of margin more keeps float rounding of the positions inside.
  const bool margin = x - start_px - reach >= 1;
  const SubpixelWindow& window = window_out->emplace(left, right, x, y, slope_x, slope_y, o,
                                                     margin ? WindowKernel::kFastest : WindowKernel::kPortable);
  const int nwin = window.size();
  const double lmean = double(window.left_sum()) / nwin;
  result.std_dn = std::sqrt(std::max(0.0, double(window.left_sum2()) / nwin - lmean * lmean));
  if (result.std_dn <= 0) return result;

  // Gauss-Newton on (d, gain, offset); residual e = l - gain*r - offset with
  // r sampled at x+u - d - gx*u - gy*v, so de/dd = gain * r' and the
  // Jacobian row is J = (gain r', -r, -1).
  double d = start_px, gain = 1.0, offset = 0.0;
  FitPassSums s;           // of the last pass, for the ZNCC
  double variance_dd = 0;  // (J^T J)^-1 [d, d] times the residual variance, of the last pass
  for (int it = 0; it < o.max_iterations; ++it) {
#if defined(__AVX2__)
    s = window.is_vector() ? FitPassVector(window.vector_view(), d, float(gain), float(offset))
                           : window.FitPass(d, float(gain), float(offset));
#else
    s = window.FitPass(d, float(gain), float(offset));
#endif
    // The normal matrix J^T J and J^T e.
    const double jtj_dd = gain * gain * s.gg, jtj_dgain = -gain * s.gr, jtj_doffset = -gain * s.g;
    const double jtj_gain2 = s.rr, jtj_gain_offset = s.r, jtj_offset2 = nwin;
    const double minus_jte[3] = {-gain * s.ge, s.re, s.e};
    double step[3], inverse_dd;
    SolveSymmetric3(jtj_dd, jtj_dgain, jtj_doffset, jtj_gain2, jtj_gain_offset, jtj_offset2, minus_jte, step,
                    &inverse_dd);
    if (!(std::isfinite(step[0]) && std::isfinite(step[1]) && std::isfinite(step[2]))) return result;
    {
      // The residual sum of squares e'e of the pass, expanded in the sums
      // the pass has (e = l - gain r - offset, with the pass's float gain
      // and offset), then after the step as the linearised model predicts
      // it (e'e + step . J'e), over n - 3 degrees of freedom: the variance
      // of a pixel's misfit, sensor noise and what the model does not
      // capture (speckle that differs between the views).
      const double a = float(gain), b = float(offset);
      const double ee = double(window.left_sum2()) - 2 * a * s.lr - 2 * b * double(window.left_sum()) + a * a * s.rr +
                        2 * a * b * s.r + nwin * b * b;
      const double rss = std::max(0.0, ee - (minus_jte[0] * step[0] + minus_jte[1] * step[1] + minus_jte[2] * step[2]));
      variance_dd = inverse_dd * rss / (nwin - 3);
    }
    d += step[0];
    gain += step[1];
    offset += step[2];
    if (std::abs(d - start_px) > o.max_shift_px) return result;
    // The ZNCC below is that of the last pass, taken before this last step
    // (< converged_step_px away): close enough for a threshold.
    if (std::abs(step[0]) < o.converged_step_px) break;
  }
  if (!(gain > 0)) return result;
  const double rmean = s.r / nwin;
  const double rvar = s.rr / nwin - rmean * rmean;
  const double cov = s.lr / nwin - lmean * rmean;
  result.zncc = rvar > 0 ? cov / (std::sqrt(rvar) * result.std_dn) : 0.0;
  result.disparity_px = d;
  result.disparity_sigma_px = std::sqrt(std::max(0.0, variance_dd));
  result.ok = true;
  return result;
}

double WindowZncc(const cv::Mat& left, const cv::Mat& right, int x, int y, double d, double slope_x, double slope_y,
                  const SubpixelOptions& o) {
  // Linear interpolation: this is a coarse test (is the match distinct?),
  // at a third of the Lanczos cost.
  return WindowZnccProbe(left, right, x, y, slope_x, slope_y, o).At(d);
}

}  // namespace stereorig
