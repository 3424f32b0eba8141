#include "reconstruct/disparity_slopes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// WindowMaskMomentSums with integers of type Int, which must hold 81 x^2,
// 81 y^2 and 81 x y. The loops are plain and fixed-length, so the compiler
// vectorises them (with int32, 8 pixels an instruction).
template <class Int>
MaskMomentSums MomentSums(const cv::Mat& disparity) {
  const int rows = disparity.rows, cols = disparity.cols, h = kSlopeWindowHalfPx, k = 2 * h + 1;
  // Per row, the window sums along x of m, x m, x^2 m (m: valid), summed
  // directly from the row's moments padded by h zeros at either end.
  std::vector<Int> row_n(size_t(rows) * cols), row_x(row_n.size()), row_xx(row_n.size());
  std::vector<Int> m(cols + 2 * h), mx(m.size()), mxx(m.size());
  for (int y = 0; y < rows; ++y) {
    const float* in = disparity.ptr<float>(y);
    for (int x = 0; x < cols; ++x) {
      const Int valid = !std::isnan(in[x]);
      m[x + h] = valid, mx[x + h] = valid * Int(x), mxx[x + h] = valid * Int(x) * Int(x);
    }
    Int *n = &row_n[size_t(y) * cols], *sx = &row_x[size_t(y) * cols], *sxx = &row_xx[size_t(y) * cols];
    for (int x = 0; x < cols; ++x) {
      Int a = 0, b = 0, c = 0;
      for (int j = 0; j < k; ++j) a += m[x + j], b += mx[x + j], c += mxx[x + j];
      n[x] = a, sx[x] = b, sxx[x] = c;
    }
  }
  // Then running sums down the columns over rows y - h .. y + h, a row r's
  // sums weighted by 1, r or r^2 for the moments in y.
  MaskMomentSums out;
  for (cv::Mat* mat : {&out.n, &out.x, &out.y, &out.xx, &out.yy, &out.xy}) mat->create(disparity.size(), CV_32FC1);
  std::vector<Int> sn(cols), sx(cols), sy(cols), sxx(cols), syy(cols), sxy(cols);
  auto add_row = [&](int r, Int sign) {
    const Int *n = &row_n[size_t(r) * cols], *x = &row_x[size_t(r) * cols], *xx = &row_xx[size_t(r) * cols];
    const Int wy = sign * Int(r), wyy = sign * Int(r) * Int(r);
    for (int c = 0; c < cols; ++c) {
      sn[c] += sign * n[c], sx[c] += sign * x[c], sxx[c] += sign * xx[c];
      sy[c] += wy * n[c], syy[c] += wyy * n[c], sxy[c] += wy * x[c];
    }
  };
  for (int r = 0; r < std::min(h, rows); ++r) add_row(r, 1);
  for (int y = 0; y < rows; ++y) {
    if (y + h < rows) add_row(y + h, 1);
    float *n = out.n.ptr<float>(y), *x = out.x.ptr<float>(y), *yv = out.y.ptr<float>(y);
    float *xx = out.xx.ptr<float>(y), *yy = out.yy.ptr<float>(y), *xy = out.xy.ptr<float>(y);
    for (int c = 0; c < cols; ++c) {  // exact integers: one rounding each, to nearest
      n[c] = float(sn[c]), x[c] = float(sx[c]), yv[c] = float(sy[c]);
      xx[c] = float(sxx[c]), yy[c] = float(syy[c]), xy[c] = float(sxy[c]);
    }
    if (y - h >= 0) add_row(y - h, -1);
  }
  return out;
}

}  // namespace

bool IsSurfaceSlope(double slope_x, double slope_y) {
  return slope_x <= kMaxSurfaceSlope && std::abs(slope_y) <= kMaxSurfaceSlope;
}

MaskMomentSums WindowMaskMomentSums(const cv::Mat& disparity) {
  STEREORIG_CHECK(disparity.type() == CV_32FC1);
  // 81 * 4095^2 < 2^31: int32 (the demo's maps are ~430 x 540 px).
  constexpr int kInt32MaxPx = 4096;
  if (disparity.cols <= kInt32MaxPx && disparity.rows <= kInt32MaxPx) return MomentSums<int32_t>(disparity);
  return MomentSums<int64_t>(disparity);
}

void DisparitySlopes(const cv::Mat& disparity, cv::Mat* slope_x, cv::Mat* slope_y, cv::Mat* plane) {
  const cv::Size k(2 * kSlopeWindowHalfPx + 1, 2 * kSlopeWindowHalfPx + 1);
  // The disparities' moments per pixel (x d, y d rounded once in float),
  // then their window sums (cv::boxFilter: running sums in double).
  cv::Mat md(disparity.size(), CV_32FC1), mxd(disparity.size(), CV_32FC1), myd(disparity.size(), CV_32FC1);
  for (int y = 0; y < disparity.rows; ++y) {
    const float* in = disparity.ptr<float>(y);
    float *md_row = md.ptr<float>(y), *mxd_row = mxd.ptr<float>(y), *myd_row = myd.ptr<float>(y);
    const float fy = float(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = in[x], fx = float(x);
      const bool valid = !std::isnan(d);
      md_row[x] = valid ? d : 0.f;
      mxd_row[x] = valid ? fx * d : 0.f;
      myd_row[x] = valid ? fy * d : 0.f;
    }
  }
  auto box = [&](const cv::Mat& a) {
    cv::Mat out;
    cv::boxFilter(a, out, CV_32F, k, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    return out;
  };
  const cv::Mat s_d = box(md), s_xd = box(mxd), s_yd = box(myd);
  const MaskMomentSums s = WindowMaskMomentSums(disparity);
  // slope_x, slope_y: views of the caller's maps (region size), written in place.
  STEREORIG_CHECK(slope_x->size() == disparity.size() && slope_y->size() == disparity.size());
  slope_x->setTo(0);
  slope_y->setTo(0);
  *plane = cv::Mat(disparity.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  for (int y = 0; y < disparity.rows; ++y) {
    const float *n_row = s.n.ptr<float>(y), *x_row = s.x.ptr<float>(y), *y_row = s.y.ptr<float>(y),
                *d_row = s_d.ptr<float>(y), *xx_row = s.xx.ptr<float>(y), *yy_row = s.yy.ptr<float>(y),
                *xy_row = s.xy.ptr<float>(y), *xd_row = s_xd.ptr<float>(y), *yd_row = s_yd.ptr<float>(y);
    float *gx_out = slope_x->ptr<float>(y), *gy_out = slope_y->ptr<float>(y), *plane_out = plane->ptr<float>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const double n = n_row[x];
      if (n < 12) continue;
      const double mxv = x_row[x] / n, myv = y_row[x] / n, md_ = d_row[x] / n;
      const double cxx = xx_row[x] / n - mxv * mxv, cyy = yy_row[x] / n - myv * myv;
      const double cxy = xy_row[x] / n - mxv * myv;
      const double cxd = xd_row[x] / n - mxv * md_, cyd = yd_row[x] / n - myv * md_;
      const double det = cxx * cyy - cxy * cxy;
      if (!(det > 1e-6)) continue;
      const double gx = (cyy * cxd - cxy * cyd) / det, gy = (cxx * cyd - cxy * cxd) / det;
      if (!IsSurfaceSlope(gx, gy)) continue;
      gx_out[x] = float(gx);
      gy_out[x] = float(gy);
      plane_out[x] = float(md_ + gx * (x - mxv) + gy * (y - myv));
    }
  }
}

}  // namespace stereorig
