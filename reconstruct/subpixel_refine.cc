#include "reconstruct/subpixel_refine.h"

#include <Eigen/Dense>
#include <cstdint>
#include <cmath>

#include "calib/core/input_error.h"

namespace stereorig {

void SubpixelOptions::Check() const {
  if (half_width_px < 1 || half_width_px > 30) throw InputError("subpixel.half_width_px", "must be in [1, 30]");
  if (half_height_px < 0 || half_height_px > 30) throw InputError("subpixel.half_height_px", "must be in [0, 30]");
  if (max_iterations < 1 || max_iterations > 50) throw InputError("subpixel.max_iterations", "must be in [1, 50]");
  if (!(max_shift_px > 0 && max_shift_px <= 4)) throw InputError("subpixel.max_shift_px", "must be in (0, 4] px");
}

namespace {

// Lanczos-3 kernel L(s) = sinc(s) sinc(s/3) and its derivative.
inline void Lanczos3(double s, double* value, double* slope) {
  if (std::abs(s) < 1e-8) {
    *value = 1.0;
    *slope = 0.0;
    return;
  }
  if (std::abs(s) >= 3.0) {
    *value = *slope = 0.0;
    return;
  }
  const double a = M_PI * s, b = a / 3.0;
  const double sa = std::sin(a), sb = std::sin(b), ca = std::cos(a), cb = std::cos(b);
  const double num = 3.0 * sa * sb, den = a * a;
  *value = num / den;
  // d/ds of 3 sin(a) sin(b) / a^2 with a = pi s, b = pi s / 3.
  const double dnum = 3.0 * M_PI * (ca * sb + sa * cb / 3.0);
  const double dden = 2.0 * M_PI * a;
  *slope = (dnum * den - num * dden) / (den * den);
}

// Weights of the taps i0-2 .. i0+3 for a sample at i0 + t, t in [0,1), and of
// its derivative along x; normalised to sum to 1 (so a constant is exact).
inline void LanczosWeights(double t, double w[6], double g[6]) {
  double sw = 0, sg = 0;
  for (int k = 0; k < 6; ++k) {
    Lanczos3(t - (k - 2), &w[k], &g[k]);
    sw += w[k];
    sg += g[k];
  }
  for (int k = 0; k < 6; ++k) {
    g[k] = (g[k] * sw - w[k] * sg) / (sw * sw);
    w[k] /= sw;
  }
}

}  // namespace

SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px,
                               const SubpixelOptions& o) {
  SubpixelResult result;
  const int hw = o.half_width_px, hh = o.half_height_px;
  if (y - hh < 0 || y + hh >= left.rows || x - hw < 0 || x + hw >= left.cols) return result;
  const int nwin = (2 * hw + 1) * (2 * hh + 1);
  double lsum = 0, lsum2 = 0;
  for (int v = -hh; v <= hh; ++v) {
    const uint8_t* lrow = left.ptr<uint8_t>(y + v);
    for (int u = -hw; u <= hw; ++u) {
      lsum += lrow[x + u];
      lsum2 += double(lrow[x + u]) * lrow[x + u];
    }
  }
  const double lmean = lsum / nwin;
  result.std_dn = std::sqrt(std::max(0.0, lsum2 / nwin - lmean * lmean));
  if (result.std_dn <= 0) return result;

  // Gauss-Newton on (d, gain, offset). The right row is interpolated with a
  // 6-tap Lanczos-3 kernel: a cubic's phase error on the ~1 px wide laser
  // lines leaves a +-0.02 px sawtooth in d (peak locking by the
  // interpolator); Lanczos-3 keeps it below the noise. All samples of the
  // window share the fractional position, so the weights are computed once
  // per iteration.
  double d = start_px, gain = 1.0, offset = 0.0;
  bool inside = true;
  const double n = nwin;
  for (int it = 0; it < o.max_iterations; ++it) {
    const double xr0 = x - d;
    const int i0 = int(std::floor(xr0));
    if (i0 - hw - 2 < 0 || i0 + hw + 3 >= right.cols) {
      inside = false;
      break;
    }
    double w[6], g[6];
    LanczosWeights(xr0 - i0, w, g);
    double srr = 0, sjj = 0, sjr = 0, sj = 0, sr = 0, sjl = 0, srl = 0, sl = 0;
    for (int v = -hh; v <= hh; ++v) {
      const uint8_t* lrow = left.ptr<uint8_t>(y + v) + x;
      const uint8_t* rrow = right.ptr<uint8_t>(y + v) + i0;
      for (int u = -hw; u <= hw; ++u) {
        const uint8_t* p = rrow + u - 2;
        const double r = w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3] * p[3] + w[4] * p[4] + w[5] * p[5];
        const double rg = g[0] * p[0] + g[1] * p[1] + g[2] * p[2] + g[3] * p[3] + g[4] * p[4] + g[5] * p[5];
        // residual e = l - gain*r - offset; R is sampled at x+u-d, so
        // de/dd = gain * rg.
        const double j = gain * rg;
        const double e = lrow[u] - gain * r - offset;
        sjj += j * j;
        sjr += j * r;
        sj += j;
        srr += r * r;
        sr += r;
        sjl += j * e;
        srl += r * e;
        sl += e;
      }
    }
    // Normal equations for (d, gain, offset), J = (j, -r, -1).
    Eigen::Matrix3d jtj;
    jtj << sjj, -sjr, -sj,  //
        -sjr, srr, sr,      //
        -sj, sr, n;
    const Eigen::Vector3d jte(sjl, -srl, -sl);
    const Eigen::Vector3d step = jtj.inverse() * (-jte);
    if (!step.allFinite()) {
      inside = false;
      break;
    }
    d += step[0];
    gain += step[1];
    offset += step[2];
    if (std::abs(d - start_px) > o.max_shift_px) {
      inside = false;
      break;
    }
    if (std::abs(step[0]) < 2e-3) break;
  }
  if (!inside || !(gain > 0)) return result;

  // ZNCC of the final alignment.
  const double xr0 = x - d;
  const int i0 = int(std::floor(xr0));
  if (i0 - hw - 2 < 0 || i0 + hw + 3 >= right.cols) return result;
  double w[6], g[6];
  LanczosWeights(xr0 - i0, w, g);
  double rs = 0, rs2 = 0, lr = 0;
  for (int v = -hh; v <= hh; ++v) {
    const uint8_t* lrow = left.ptr<uint8_t>(y + v) + x;
    const uint8_t* rrow = right.ptr<uint8_t>(y + v) + i0;
    for (int u = -hw; u <= hw; ++u) {
      const uint8_t* p = rrow + u - 2;
      const double r = w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3] * p[3] + w[4] * p[4] + w[5] * p[5];
      rs += r;
      rs2 += r * r;
      lr += r * lrow[u];
    }
  }
  const double rmean = rs / nwin;
  const double rvar = rs2 / nwin - rmean * rmean;
  const double cov = lr / nwin - lmean * rmean;
  result.zncc = rvar > 0 ? cov / (std::sqrt(rvar) * result.std_dn) : 0.0;
  result.disparity_px = d;
  result.ok = true;
  return result;
}

}  // namespace stereorig
