// RefineDisparityAndRowOffset (subpixel_refine.h): apart from the per-pixel
// fit because it solves its 4x4 system with Eigen, and Eigen templates must
// not be instantiated in the files built with -march=native
// (reconstruct/CMakeLists.txt). Its samples come from the per-pixel fit's
// window sampler (subpixel_window.h), which is.
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <vector>

#include "reconstruct/row_offset_sums.h"
#include "reconstruct/subpixel_refine.h"
#include "reconstruct/subpixel_window.h"

namespace stereorig {

namespace {

// Cubic convolution (Keys, a = -0.5) weights of rows i0-1 .. i0+2 for a
// sample at i0 + t, t in [0, 1), and their derivatives along t.
void CubicRows(double t, double w[4], double dw[4]) {
  for (int k = 0; k < 4; ++k) {
    const double s = t - (k - 1), a = std::abs(s), sign = s < 0 ? -1.0 : 1.0;
    if (a <= 1) {
      w[k] = (1.5 * a - 2.5) * a * a + 1;
      dw[k] = sign * (4.5 * a - 5.0) * a;
    } else if (a < 2) {
      w[k] = ((-0.5 * a + 2.5) * a - 4) * a + 2;
      dw[k] = sign * ((-1.5 * a + 5.0) * a - 4);
    } else {
      w[k] = dw[k] = 0;
    }
  }
}

}  // namespace

RowOffsetResult RefineDisparityAndRowOffset(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px,
                                            double slope_x, double slope_y, const SubpixelOptions& o) {
  RowOffsetResult result;
  const int hw = o.half_width_px, hh = o.half_height_px;
  // Rows y-hh-1+floor(dy) .. y+hh+2+floor(dy), |dy| <= 1.
  if (y - hh - 2 < 0 || y + hh + 3 >= left.rows || x - hw < 0 || x + hw >= left.cols) return result;
  const double reach = hw + std::abs(slope_x) * hw + std::abs(slope_y) * hh + o.max_shift_px + 4;
  if (x - start_px - reach < 0 || x - start_px + reach >= right.cols) return result;
  // The right rows are sampled by the sub-pixel fit's window sampler (AVX2
  // where built so; it reads 2 columns more to the left, see
  // RefineDisparity), once per cubic row per pass.
  const bool margin = x - start_px - reach >= 1;
  const SubpixelWindow window(left, right, x, y, slope_x, slope_y, o,
                              margin ? WindowKernel::kFastest : WindowKernel::kPortable);
  const int nwin = window.size(), npad = window.padded_size();
  const double lmean = double(window.left_sum()) / nwin;
  const double lstd = std::sqrt(std::max(0.0, double(window.left_sum2()) / nwin - lmean * lmean));
  if (!(lstd > 0)) return result;
  // Left values, then the 4 rows' right values and slopes, npad each.
  std::vector<float> buffer(9 * size_t(npad));
  float* l = buffer.data();
  for (int v = -hh, s = 0; v <= hh; ++v)
    for (int u = -hw; u <= hw; ++u, ++s) l[s] = left.at<uint8_t>(y + v, x + u);
  double d = start_px, dy = 0, gain = 1, offset = 0;
  double rs = 0, rs2 = 0, lr = 0;
  for (int it = 0; it < o.max_iterations + 2; ++it) {
    const int i0 = int(std::floor(dy));
    double w[4], dw[4];
    CubicRows(dy - i0, w, dw);
    const float* rk[4];
    const float* gk[4];
    for (int k = 0; k < 4; ++k) {
      float* r = buffer.data() + (1 + 2 * k) * size_t(npad);
      float* g = r + npad;
      window.Sample(d, i0 - 1 + k, r, g);
      rk[k] = r, gk[k] = g;
    }
    // J = de/d(d, dy, gain, offset) = (gain rx, -gain ry, -r, -1): the
    // sums of r x, r y, r over the samples give J^T J and J^T e.
    const RowOffsetSums t = RowOffsetPassSums(l, rk, gk, w, dw, gain, offset, nwin);
    const double sxx = t.sxx, sxy = t.sxy, sxr = t.sxr, sx = t.sx, syy = t.syy, syr = t.syr, sy = t.sy;
    const double srr = t.srr, sr = t.sr, sxe = t.sxe, sye = t.sye, sre = t.sre, se = t.se, slr = t.slr;
    rs = sr, rs2 = srr, lr = slr;
    const double a = gain;
    Eigen::Matrix4d jtj;
    jtj << a * a * sxx, -a * a * sxy, -a * sxr, -a * sx,  //
        -a * a * sxy, a * a * syy, a * syr, a * sy,       //
        -a * sxr, a * syr, srr, sr,                       //
        -a * sx, a * sy, sr, double(nwin);
    const Eigen::Vector4d jte(a * sxe, -a * sye, -sre, -se);
    const Eigen::Vector4d step = -jtj.ldlt().solve(jte);
    if (!step.allFinite()) return result;
    d += step[0], dy += step[1], gain += step[2], offset += step[3];
    if (std::abs(d - start_px) > o.max_shift_px || std::abs(dy) > 1.0) return result;
    if (std::abs(step[0]) < 0.01 && std::abs(step[1]) < 0.01) break;
  }
  if (!(gain > 0)) return result;
  const double rmean = rs / nwin, rvar = rs2 / nwin - rmean * rmean;
  result.zncc = rvar > 0 ? (lr / nwin - lmean * rmean) / (std::sqrt(rvar) * lstd) : 0.0;
  result.disparity_px = d;
  result.row_offset_px = dy;
  result.ok = true;
  return result;
}

}  // namespace stereorig
