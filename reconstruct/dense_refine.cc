#include "reconstruct/dense_refine.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "reconstruct/lanczos_taps.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/window_sums.h"

namespace stereorig {

SubpixelResult DenseRefineResult::At(int x, int y) const {
  SubpixelResult r;
  const int xx = x - roi.x, yy = y - roi.y;
  if (xx < 0 || yy < 0 || xx >= roi.width || yy >= roi.height || !ok.at<uint8_t>(yy, xx)) return r;
  r.ok = true;
  r.disparity_px = disparity_px.at<float>(yy, xx);
  r.zncc = zncc.at<float>(yy, xx);
  r.std_dn = std_dn.at<float>(yy, xx);
  return r;
}

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The window sums of one pass, in the order the products are formed: the
// warped right value r and slope g, the left value l.
enum Sum { kGG, kGR, kG, kRR, kR, kGL, kRL, kL, kLL, kNumSums };

// Right image sampled at x - field(x) (value and slope), NaN where the field
// is NaN or the taps leave the image.
void Warp(const cv::Mat& right, const cv::Rect& roi, const cv::Mat& field, int num_threads, cv::Mat* value,
          cv::Mat* slope) {
  const LanczosTable& table = LanczosTapTable();
  const float x_max = float(right.cols - 3);
  ParallelForChunks(roi.height, num_threads, [&](int b, int e) {
    for (int yy = b; yy < e; ++yy) {
      const uint8_t* row = right.ptr<uint8_t>(roi.y + yy);
      const float* f = field.ptr<float>(yy);
      float* r = value->ptr<float>(yy);
      float* g = slope->ptr<float>(yy);
      for (int xx = 0; xx < roi.width; ++xx) {
        const float xr = float(roi.x + xx) - f[xx];
        if (!(xr >= 2.0f && xr < x_max)) {  // NaN fails too
          r[xx] = g[xx] = kNaN;
          continue;
        }
        SampleLanczos(row, xr, table, &r[xx], &g[xx]);
      }
    }
  });
}

// Solves the symmetric 3x3 system m s = rhs (Cramer's rule); false if singular.
bool Solve3(const double m[3][3], const double rhs[3], double s[3]) {
  const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;
  const double inv[3][3] = {{c00, m[0][2] * m[2][1] - m[0][1] * m[2][2], m[0][1] * m[1][2] - m[0][2] * m[1][1]},
                            {c01, m[0][0] * m[2][2] - m[0][2] * m[2][0], m[0][2] * m[1][0] - m[0][0] * m[1][2]},
                            {c02, m[0][1] * m[2][0] - m[0][0] * m[2][1], m[0][0] * m[1][1] - m[0][1] * m[1][0]}};
  for (int i = 0; i < 3; ++i) s[i] = (inv[i][0] * rhs[0] + inv[i][1] * rhs[1] + inv[i][2] * rhs[2]) / det;
  return std::isfinite(s[0]) && std::isfinite(s[1]) && std::isfinite(s[2]);
}

// The RMS residual of the field over the window of centre (xx, yy) from
// its least-squares plane there (NaN if a field value is missing): how far
// the warp is from a planar one. The plane's slopes are the refined field's
// own, not DisparitySlopes' (those, from the integer-level field, are off by
// ~0.03-0.05 px/px on curved flanks; the per-pixel fit's model is off by as
// much there).
float WarpDeviation(const cv::Mat& field, int xx, int yy, int hw, int hh) {
  const float fc = field.at<float>(yy, xx);
  float s = 0, su = 0, sv = 0, s2 = 0;
  for (int v = -hh; v <= hh; ++v) {
    const float* f = field.ptr<float>(yy + v) + xx;
    for (int u = -hw; u <= hw; ++u) {
      const float dev = f[u] - fc;
      s += dev, su += dev * float(u), sv += dev * float(v), s2 += dev * dev;
    }
  }
  // Symmetric window: the plane's terms are orthogonal.
  const float n = float((2 * hw + 1) * (2 * hh + 1));
  const float uu = n * float(hw * (hw + 1)) / 3.0f, vv = n * float(hh * (hh + 1)) / 3.0f;
  const float residual2 = s2 - s * s / n - su * su / uu - (vv > 0 ? sv * sv / vv : 0.0f);
  return std::sqrt(std::max(0.0f, residual2) / n);
}

// The field for the next pass: the plane plus the mean, over twice the
// window, of each pixel's correction to it. A pixel's own estimate carries
// its fit noise (~0.016 px on the test plane), and the next pass, warping by
// its neighbours' estimates, would add a weighted mean of theirs to each
// result (measured on the test plane: 0.022 px rms against the per-pixel
// fit's 0.016; a mean over one window: 0.017; over twice it: 0.016). A
// symmetric mean keeps a correction that is linear across it (slightly
// wrong slopes) and averages the noise; the last pass starts from it and its
// step is a full Gauss-Newton step, so the result is still each window's own
// fit.
void SmoothField(const cv::Mat& plane_px, int hw, int hh, cv::Mat* field) {
  cv::Mat correction = *field - plane_px;
  cv::patchNaNs(correction, 0);  // no plane: no correction (a NaN would run along boxFilter's running sums)
  cv::Mat mean;
  cv::boxFilter(correction, mean, CV_32F, cv::Size(4 * hw + 1, 4 * hh + 1), cv::Point(-1, -1), true,
                cv::BORDER_REPLICATE);
  *field = plane_px + mean;
}

}  // namespace

DenseRefineResult DenseRefine(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const cv::Mat& start_px,
                              const cv::Mat& plane_px, const cv::Mat& slope_x, const cv::Mat& slope_y,
                              const SubpixelOptions& o, int num_threads) {
  const int hw = o.half_width_px, hh = o.half_height_px, width = roi.width;
  const double n = (2 * hw + 1) * (2 * hh + 1);
  DenseRefineResult result;
  result.roi = roi;
  result.disparity_px = cv::Mat(roi.size(), CV_32FC1, cv::Scalar(kNaN));
  result.zncc = cv::Mat(roi.size(), CV_32FC1, cv::Scalar(0));
  result.std_dn = cv::Mat(roi.size(), CV_32FC1, cv::Scalar(0));
  result.ok = cv::Mat(roi.size(), CV_8UC1, cv::Scalar(0));
  cv::Mat field = plane_px.clone();
  cv::Mat gain(roi.size(), CV_32FC1, cv::Scalar(1)), offset(roi.size(), CV_32FC1, cv::Scalar(0));
  cv::Mat value(roi.size(), CV_32FC1), slope(roi.size(), CV_32FC1);
  const int passes = o.max_iterations;
  for (int it = 0; it < passes; ++it) {
    const bool last = it + 1 == passes;
    if (it > 0) SmoothField(plane_px, hw, hh, &field);
    Warp(right, roi, field, num_threads, &value, &slope);
    ParallelForChunks(std::max(0, roi.height - 2 * hh), num_threads, [&](int b, int e) {
      std::vector<float> column(size_t(kNumSums) * width), window(size_t(kNumSums) * width);
      for (int yy = hh + b; yy < hh + e; ++yy) {
        std::fill(column.begin(), column.end(), 0.0f);
        float* c = column.data();
        for (int v = -hh; v <= hh; ++v) {
          const float* r = value.ptr<float>(yy + v);
          const float* g = slope.ptr<float>(yy + v);
          const uint8_t* l8 = left.ptr<uint8_t>(roi.y + yy + v) + roi.x;
          for (int x = 0; x < width; ++x) {
            const float l = l8[x];
            c[kGG * width + x] += g[x] * g[x];
            c[kGR * width + x] += g[x] * r[x];
            c[kG * width + x] += g[x];
            c[kRR * width + x] += r[x] * r[x];
            c[kR * width + x] += r[x];
            c[kGL * width + x] += g[x] * l;
            c[kRL * width + x] += r[x] * l;
            c[kL * width + x] += l;
            c[kLL * width + x] += l * l;
          }
        }
        for (int k = 0; k < kNumSums; ++k) SumAlongRow(c + k * width, width, hw, window.data() + k * width);
        float* f = field.ptr<float>(yy);
        float* a_row = gain.ptr<float>(yy);
        float* b_row = offset.ptr<float>(yy);
        const float* start = start_px.ptr<float>(yy);
        for (int xx = hw; xx < width - hw; ++xx) {
          if (!std::isfinite(f[xx])) continue;
          double s[kNumSums];
          for (int k = 0; k < kNumSums; ++k) s[k] = window[k * width + xx];
          const double a = a_row[xx], off = b_row[xx];
          // RefineDisparity's normal equations, its sums expanded in the
          // gain a and offset: residual e = l - a r - off, de/dd = a g.
          const double sjj = a * a * s[kGG], sjr = a * s[kGR], sj = a * s[kG];
          const double sje = a * (s[kGL] - a * s[kGR] - off * s[kG]);
          const double sre = s[kRL] - a * s[kRR] - off * s[kR];
          const double se = s[kL] - a * s[kR] - n * off;
          const double m[3][3] = {{sjj, -sjr, -sj}, {-sjr, s[kRR], s[kR]}, {-sj, s[kR], n}};
          const double rhs[3] = {-sje, sre, se};
          double step[3];
          if (!Solve3(m, rhs, step)) continue;  // a missing warp sample is NaN here too
          if (!last) {
            // A wild step (a start outside the basin) keeps the smooth field
            // value, so the neighbours' windows stay usable.
            if (std::abs(step[0]) > o.max_shift_px) continue;
            f[xx] += float(step[0]);
            a_row[xx] += float(step[1]);
            b_row[xx] += float(step[2]);
            continue;
          }
          const double d = f[xx] + step[0];
          if (!std::isfinite(start[xx]) || std::abs(step[0]) >= o.converged_step_px || !(a + step[1] > 0) ||
              std::abs(d - start[xx]) > o.max_shift_px)
            continue;
          const int x = roi.x + xx;
          const float gx = slope_x.at<float>(yy, xx), gy = slope_y.at<float>(yy, xx);
          const double reach = hw + std::abs(gx) * hw + std::abs(gy) * hh + o.max_shift_px + 4;
          if (x - start[xx] - reach < 0 || x - start[xx] + reach >= right.cols) continue;
          if (!(WarpDeviation(field, xx, yy, hw, hh) <= kMaxWarpDeviationPx)) continue;
          const double lmean = s[kL] / n, lstd = std::sqrt(std::max(0.0, s[kLL] / n - lmean * lmean));
          if (!(lstd > 0)) continue;
          const double rmean = s[kR] / n, rvar = s[kRR] / n - rmean * rmean, cov = s[kRL] / n - lmean * rmean;
          result.disparity_px.at<float>(yy, xx) = float(d);
          result.zncc.at<float>(yy, xx) = float(rvar > 0 ? cov / (std::sqrt(rvar) * lstd) : 0.0);
          result.std_dn.at<float>(yy, xx) = float(lstd);
          result.ok.at<uint8_t>(yy, xx) = 1;
        }
      }
    });
  }
  for (int yy = 0; yy < roi.height; ++yy)
    for (int xx = 0; xx < roi.width; ++xx)
      if (std::isfinite(start_px.at<float>(yy, xx)))
        ++(result.ok.at<uint8_t>(yy, xx) ? result.num_dense : result.num_fallback);
  return result;
}

}  // namespace stereorig
