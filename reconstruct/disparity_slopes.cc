#include "reconstruct/disparity_slopes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// One row of the nine window sums (each cols floats).
struct WindowMomentRow {
  const float *n, *x, *y, *xx, *yy, *xy, *d, *xd, *yd;
};

// The nine 9x9 window sums of a row, streamed down the map: each row's
// sums along x are kept for the 9 rows a window spans (a ring), and running
// sums down the columns add the row entering the window and drop the one
// leaving it. The six mask moments are integers of type Int, which must hold
// 81 x^2, 81 y^2 and 81 x y: summed exactly. The three disparity moments
// (d, x d, y d: float, as x d and y d were rounded when they were images)
// are summed in double: exact while the sums' bits span < 53 (disparities
// of at least 2^-6 px below 2^24 px), and then equal to cv::boxFilter's
// double running sums, which this replaced (disparity_slopes_test.cc).
// Memory: 9 rows, not the ~16 map-sized images the box filters took (the
// step's page faults were ~60 % of the runtime's, measured by the bench).
template <class Int>
class MomentRows {
 public:
  explicit MomentRows(const cv::Mat& disparity) : disparity_(disparity), rows_(disparity.rows), cols_(disparity.cols) {
    const size_t ring = size_t(kWindow) * cols_;
    for (auto* v : {&hn_, &hx_, &hxx_}) v->assign(ring, 0);
    for (auto* v : {&hd_, &hxd_, &hyd_}) v->assign(ring, 0);
    for (auto* v : {&sn_, &sx_, &sxx_, &sy_, &syy_, &sxy_}) v->assign(cols_, 0);
    for (auto* v : {&sd_, &sxd_, &syd_}) v->assign(cols_, 0);
    for (auto* v : {&m_, &mx_, &mxx_}) v->assign(cols_ + 2 * kHalf, 0);
    for (auto* v : {&md_, &mxd_, &myd_}) v->assign(cols_ + 2 * kHalf, 0.f);
    out_.assign(size_t(9) * cols_, 0.f);
    for (int r = 0; r < std::min(kHalf, rows_); ++r) AddRow(r);
  }

  // Row y's sums (0 <= y < rows, called for y = 0, 1, 2, ... in order).
  const WindowMomentRow& Row(int y) {
    if (y + kHalf < rows_) AddRow(y + kHalf);
    float* o = out_.data();
    float *n = o, *x = o + cols_, *yv = o + 2 * cols_, *xx = o + 3 * cols_, *yy = o + 4 * cols_;
    float *xy = o + 5 * cols_, *d = o + 6 * cols_, *xd = o + 7 * cols_, *yd = o + 8 * cols_;
    for (int c = 0; c < cols_; ++c) {  // one rounding each, to nearest
      n[c] = float(sn_[c]), x[c] = float(sx_[c]), yv[c] = float(sy_[c]);
      xx[c] = float(sxx_[c]), yy[c] = float(syy_[c]), xy[c] = float(sxy_[c]);
      d[c] = float(sd_[c]), xd[c] = float(sxd_[c]), yd[c] = float(syd_[c]);
    }
    row_ = {n, x, yv, xx, yy, xy, d, xd, yd};
    if (y - kHalf >= 0) DropRow(y - kHalf);
    return row_;
  }

 private:
  static constexpr int kHalf = kSlopeWindowHalfPx, kWindow = 2 * kSlopeWindowHalfPx + 1;

  // Row r's sums along x into its ring slot, then into the column sums.
  void AddRow(int r) {
    const float* in = disparity_.ptr<float>(r);
    const float fy = float(r);
    for (int x = 0; x < cols_; ++x) {
      const float d = in[x], fx = float(x);
      const bool valid = !std::isnan(d);
      const Int v = valid;
      m_[x + kHalf] = v, mx_[x + kHalf] = v * Int(x), mxx_[x + kHalf] = v * Int(x) * Int(x);
      md_[x + kHalf] = valid ? d : 0.f;
      mxd_[x + kHalf] = valid ? fx * d : 0.f;
      myd_[x + kHalf] = valid ? fy * d : 0.f;
    }
    const size_t slot = size_t(r % kWindow) * cols_;
    Int *n = &hn_[slot], *sx = &hx_[slot], *sxx = &hxx_[slot];
    double *sd = &hd_[slot], *sxd = &hxd_[slot], *syd = &hyd_[slot];
    for (int x = 0; x < cols_; ++x) {
      Int a = 0, b = 0, c = 0;
      for (int j = 0; j < kWindow; ++j) a += m_[x + j], b += mx_[x + j], c += mxx_[x + j];
      n[x] = a, sx[x] = b, sxx[x] = c;
    }
    for (int x = 0; x < cols_; ++x) {
      double a = 0, b = 0, c = 0;
      for (int j = 0; j < kWindow; ++j) a += double(md_[x + j]), b += double(mxd_[x + j]), c += double(myd_[x + j]);
      sd[x] = a, sxd[x] = b, syd[x] = c;
    }
    Accumulate(r, Int(1));
  }

  void DropRow(int r) { Accumulate(r, Int(-1)); }

  // Column sums += sign * row r's sums, its y moments weighted by r, r^2.
  void Accumulate(int r, Int sign) {
    const size_t slot = size_t(r % kWindow) * cols_;
    const Int *n = &hn_[slot], *x = &hx_[slot], *xx = &hxx_[slot];
    const double *d = &hd_[slot], *xd = &hxd_[slot], *yd = &hyd_[slot];
    const Int wy = sign * Int(r), wyy = sign * Int(r) * Int(r);
    for (int c = 0; c < cols_; ++c) {
      sn_[c] += sign * n[c], sx_[c] += sign * x[c], sxx_[c] += sign * xx[c];
      sy_[c] += wy * n[c], syy_[c] += wyy * n[c], sxy_[c] += wy * x[c];
    }
    if (sign > 0)
      for (int c = 0; c < cols_; ++c) sd_[c] += d[c], sxd_[c] += xd[c], syd_[c] += yd[c];
    else
      for (int c = 0; c < cols_; ++c) sd_[c] -= d[c], sxd_[c] -= xd[c], syd_[c] -= yd[c];
  }

  const cv::Mat& disparity_;
  const int rows_, cols_;
  std::vector<Int> hn_, hx_, hxx_;                   // ring: each row's sums along x
  std::vector<double> hd_, hxd_, hyd_;               // (slot r % 9)
  std::vector<Int> sn_, sx_, sxx_, sy_, syy_, sxy_;  // running column sums
  std::vector<double> sd_, sxd_, syd_;
  std::vector<Int> m_, mx_, mxx_;  // one row's moments, h zeros either end
  std::vector<float> md_, mxd_, myd_;
  std::vector<float> out_;
  WindowMomentRow row_{};
};

template <class Int>
void SlopesWith(const cv::Mat& disparity, cv::Mat* slope_x, cv::Mat* slope_y, cv::Mat* plane) {
  MomentRows<Int> sums(disparity);
  for (int y = 0; y < disparity.rows; ++y) {
    const WindowMomentRow& s = sums.Row(y);
    float *gx_out = slope_x->ptr<float>(y), *gy_out = slope_y->ptr<float>(y), *plane_out = plane->ptr<float>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const double n = s.n[x];
      if (n < 12) continue;
      const double mxv = s.x[x] / n, myv = s.y[x] / n, md_ = s.d[x] / n;
      const double cxx = s.xx[x] / n - mxv * mxv, cyy = s.yy[x] / n - myv * myv;
      const double cxy = s.xy[x] / n - mxv * myv;
      const double cxd = s.xd[x] / n - mxv * md_, cyd = s.yd[x] / n - myv * md_;
      const double det = cxx * cyy - cxy * cxy;
      if (!(det > 1e-6)) continue;
      const double gx = (cyy * cxd - cxy * cyd) / det, gy = (cxx * cyd - cxy * cxd) / det;
      if (std::abs(gx) > 1.5 || std::abs(gy) > 1.5) continue;  // a depth edge, not a surface
      gx_out[x] = float(gx);
      gy_out[x] = float(gy);
      plane_out[x] = float(md_ + gx * (x - mxv) + gy * (y - myv));
    }
  }
}

template <class Int>
WindowMomentSums SumMapsWith(const cv::Mat& disparity) {
  WindowMomentSums out;
  cv::Mat* maps[] = {&out.n, &out.x, &out.y, &out.xx, &out.yy, &out.xy, &out.d, &out.xd, &out.yd};
  for (cv::Mat* m : maps) m->create(disparity.size(), CV_32FC1);
  MomentRows<Int> sums(disparity);
  for (int y = 0; y < disparity.rows; ++y) {
    const WindowMomentRow& s = sums.Row(y);
    const float* rows[] = {s.n, s.x, s.y, s.xx, s.yy, s.xy, s.d, s.xd, s.yd};
    for (int i = 0; i < 9; ++i) std::copy(rows[i], rows[i] + disparity.cols, maps[i]->ptr<float>(y));
  }
  return out;
}

// 81 * 4095^2 < 2^31: int32 (the demo's maps are ~430 x 540 px).
constexpr int kInt32MaxPx = 4096;
bool Int32Holds(const cv::Mat& disparity) { return disparity.cols <= kInt32MaxPx && disparity.rows <= kInt32MaxPx; }

}  // namespace

WindowMomentSums WindowMomentSumMaps(const cv::Mat& disparity) {
  STEREORIG_CHECK(disparity.type() == CV_32FC1);
  return Int32Holds(disparity) ? SumMapsWith<int32_t>(disparity) : SumMapsWith<int64_t>(disparity);
}

void DisparitySlopes(const cv::Mat& disparity, cv::Mat* slope_x, cv::Mat* slope_y, cv::Mat* plane) {
  STEREORIG_CHECK(disparity.type() == CV_32FC1);
  // slope_x, slope_y: views of the caller's maps (region size), written in place.
  STEREORIG_CHECK(slope_x->size() == disparity.size() && slope_y->size() == disparity.size());
  slope_x->setTo(0);
  slope_y->setTo(0);
  *plane = cv::Mat(disparity.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  if (Int32Holds(disparity))
    SlopesWith<int32_t>(disparity, slope_x, slope_y, plane);
  else
    SlopesWith<int64_t>(disparity, slope_x, slope_y, plane);
}

}  // namespace stereorig
