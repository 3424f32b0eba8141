// RefineDisparityAndRowOffset (subpixel_refine.h): apart from the per-pixel
// fit because it solves its 4x4 system with Eigen, and Eigen templates must
// not be instantiated in the files built with -march=native
// (reconstruct/CMakeLists.txt).
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>

#include "reconstruct/lanczos_taps.h"
#include "reconstruct/subpixel_refine.h"

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
