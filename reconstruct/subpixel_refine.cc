#include "reconstruct/subpixel_refine.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>

#include "calib/core/input_error.h"
#include "reconstruct/lanczos_taps.h"

namespace stereorig {

void SubpixelOptions::Check() const {
  if (half_width_px < 1 || half_width_px > 30) throw InputError("subpixel.half_width_px", "must be in [1, 30]");
  if (half_height_px < 0 || half_height_px > 30) throw InputError("subpixel.half_height_px", "must be in [0, 30]");
  if (max_iterations < 1 || max_iterations > 50) throw InputError("subpixel.max_iterations", "must be in [1, 50]");
  if (!(converged_step_px > 0 && converged_step_px < 0.5))
    throw InputError("subpixel.converged_step_px", "must be in (0, 0.5) px");
  if (!(max_shift_px > 0 && max_shift_px <= 4)) throw InputError("subpixel.max_shift_px", "must be in (0, 4] px");
}

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

SubpixelResult RefineDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px, double slope_x,
                               double slope_y, const SubpixelOptions& o) {
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
  // The sampled right columns must stay inside the image (6 taps).
  const double reach = hw + std::abs(slope_x) * hw + std::abs(slope_y) * hh + o.max_shift_px + 4;
  if (x - start_px - reach < 0 || x - start_px + reach >= right.cols) return result;
  const LanczosTable& table = LanczosTapTable();

  // Gauss-Newton on (d, gain, offset); residual e = l - gain*r - offset with
  // r sampled at x+u - d - gx*u - gy*v, so de/dd = gain * r'.
  double d = start_px, gain = 1.0, offset = 0.0;
  double rs = 0, rs2 = 0, lr = 0;  // sums of the last pass, for the ZNCC
  for (int it = 0; it < o.max_iterations; ++it) {
    float sjj = 0, sjr = 0, sj = 0, srr = 0, sr = 0, sje = 0, sre = 0, se = 0, slr = 0;
    const float fgain = float(gain), foffset = float(offset);
    for (int v = -hh; v <= hh; ++v) {
      const uint8_t* lrow = left.ptr<uint8_t>(y + v) + x;
      const uint8_t* rrow = right.ptr<uint8_t>(y + v);
      const float row_start = float(x - d - slope_y * v), stride = float(1.0 - slope_x);
      for (int u = -hw; u <= hw; ++u) {
        float r, rg;
        SampleLanczos(rrow, row_start + float(u) * stride, table, &r, &rg);
        const float l = lrow[u];
        const float j = fgain * rg;
        const float e = l - fgain * r - foffset;
        sjj += j * j, sjr += j * r, sj += j;
        srr += r * r, sr += r;
        sje += j * e, sre += r * e, se += e;
        slr += l * r;
      }
    }
    rs = sr, rs2 = srr, lr = slr;
    Eigen::Matrix3d jtj;
    jtj << sjj, -sjr, -sj,  //
        -sjr, srr, sr,      //
        -sj, sr, double(nwin);
    const Eigen::Vector3d step = jtj.inverse() * (-Eigen::Vector3d(sje, -sre, -se));
    if (!step.allFinite()) return result;
    d += step[0];
    gain += step[1];
    offset += step[2];
    if (std::abs(d - start_px) > o.max_shift_px) return result;
    // The ZNCC below is that of the last pass, taken before this last step
    // (< converged_step_px away): close enough for a threshold.
    if (std::abs(step[0]) < o.converged_step_px) break;
  }
  if (!(gain > 0)) return result;
  const double rmean = rs / nwin;
  const double rvar = rs2 / nwin - rmean * rmean;
  const double cov = lr / nwin - lmean * rmean;
  result.zncc = rvar > 0 ? cov / (std::sqrt(rvar) * result.std_dn) : 0.0;
  result.disparity_px = d;
  result.ok = true;
  return result;
}

double WindowZncc(const cv::Mat& left, const cv::Mat& right, int x, int y, double d, double slope_x, double slope_y,
                  const SubpixelOptions& o) {
  const int hw = o.half_width_px, hh = o.half_height_px;
  if (y - hh < 0 || y + hh >= left.rows || x - hw < 0 || x + hw >= left.cols) return -1;
  const double reach = hw + std::abs(slope_x) * hw + std::abs(slope_y) * hh + 4;
  if (x - d - reach < 0 || x - d + reach >= right.cols) return -1;
  // Linear interpolation: this is a coarse test (is the match distinct?),
  // at a third of the Lanczos cost.
  float ls = 0, ls2 = 0, rs = 0, rs2 = 0, lr = 0;
  for (int v = -hh; v <= hh; ++v) {
    const uint8_t* lrow = left.ptr<uint8_t>(y + v) + x;
    const uint8_t* rrow = right.ptr<uint8_t>(y + v);
    const float row_start = float(x - d - slope_y * v), stride = float(1.0 - slope_x);
    for (int u = -hw; u <= hw; ++u) {
      const float xr = row_start + float(u) * stride;
      const int i0 = int(xr);
      const float t = xr - float(i0);
      const float r = (1 - t) * rrow[i0] + t * rrow[i0 + 1];
      const float l = lrow[u];
      ls += l, ls2 += l * l, rs += r, rs2 += r * r, lr += l * r;
    }
  }
  const int n = (2 * hw + 1) * (2 * hh + 1);
  const double lv = double(ls2) / n - double(ls / n) * (ls / n), rv = double(rs2) / n - double(rs / n) * (rs / n);
  if (!(lv > 0 && rv > 0)) return -1;
  return (lr / n - (ls / n) * (rs / n)) / std::sqrt(lv * rv);
}

RowOffsetResult RefineDisparityAndRowOffset(const cv::Mat& left, const cv::Mat& right, int x, int y, double start_px,
                                            double slope_x, double slope_y, const SubpixelOptions& o) {
  RowOffsetResult result;
  const int hw = o.half_width_px, hh = o.half_height_px;
  // Rows y-hh-1+floor(dy) .. y+hh+2+floor(dy), |dy| <= 1.
  if (y - hh - 2 < 0 || y + hh + 3 >= left.rows || x - hw < 0 || x + hw >= left.cols) return result;
  const double reach = hw + std::abs(slope_x) * hw + std::abs(slope_y) * hh + o.max_shift_px + 4;
  if (x - start_px - reach < 0 || x - start_px + reach >= right.cols) return result;
  const int nwin = (2 * hw + 1) * (2 * hh + 1);
  double lsum = 0, lsum2 = 0;
  for (int v = -hh; v <= hh; ++v)
    for (int u = -hw; u <= hw; ++u) {
      const double l = left.at<uint8_t>(y + v, x + u);
      lsum += l, lsum2 += l * l;
    }
  const double lmean = lsum / nwin, lstd = std::sqrt(std::max(0.0, lsum2 / nwin - lmean * lmean));
  if (!(lstd > 0)) return result;
  const LanczosTable& table = LanczosTapTable();
  double d = start_px, dy = 0, gain = 1, offset = 0;
  double rs = 0, rs2 = 0, lr = 0;
  for (int it = 0; it < o.max_iterations + 2; ++it) {
    const int i0 = int(std::floor(dy));
    double w[4], dw[4];
    CubicRows(dy - i0, w, dw);
    Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
    Eigen::Vector4d jte = Eigen::Vector4d::Zero();
    rs = rs2 = lr = 0;
    for (int v = -hh; v <= hh; ++v) {
      const uint8_t* lrow = left.ptr<uint8_t>(y + v) + x;
      const float row_start = float(x - d - slope_y * v), stride = float(1.0 - slope_x);
      for (int u = -hw; u <= hw; ++u) {
        double r = 0, rx = 0, ry = 0;
        for (int k = 0; k < 4; ++k) {
          float value, slope;
          SampleLanczos(right.ptr<uint8_t>(y + v + i0 - 1 + k), row_start + float(u) * stride, table, &value, &slope);
          r += w[k] * value, rx += w[k] * slope, ry += dw[k] * value;
        }
        const double l = lrow[u];
        const double e = l - gain * r - offset;
        // de/d(d, dy, gain, offset)
        const Eigen::Vector4d j(gain * rx, -gain * ry, -r, -1.0);
        jtj += j * j.transpose();
        jte += j * e;
        rs += r, rs2 += r * r, lr += l * r;
      }
    }
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
