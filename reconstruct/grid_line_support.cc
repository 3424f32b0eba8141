#include "reconstruct/grid_line_support.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

void GridLineOptions::Check() const {
  if (!(min_prominence_dn > 0 && min_prominence_dn <= 255))
    throw InputError("grid_line_min_prominence_dn", "must be in (0, 255] DN");
  if (radius_px < 1 || radius_px > 30) throw InputError("grid_line_radius_px", "must be in [1, 30] px");
  if (min_ridge_px < 1 || min_ridge_px > (2 * radius_px + 1) * (2 * radius_px + 1))
    throw InputError("grid_line_min_ridge_px", "must be in [1, (2 grid_line_radius_px + 1)^2]");
}

namespace {

// The ridges along one direction (GridRidges' test, height >= c), OR-ed
// into `ridges` (CV_8UC1) as 255. along_x: along the rows (neighbours left
// and right), else along the columns. Only pixels at least k from the
// image's edge in that direction are tested.
void OrRidgesAlong(const cv::Mat& grey, int k, int c, bool along_x, cv::Mat* ridges) {
  const int n = along_x ? grey.cols : grey.rows;
  if (n < 2 * k + 1) return;
  // The lowest grey within k before the pixel (excluding it) and within k
  // after it, by erosion with a one-sided line (erode's border value is
  // the largest grey, so it never wins; the tested pixels need none).
  cv::Mat before_kernel = cv::Mat::ones(1, k + 1, CV_8UC1), after_kernel = cv::Mat::ones(1, k + 1, CV_8UC1);
  before_kernel.at<uint8_t>(0, k) = 0;
  after_kernel.at<uint8_t>(0, 0) = 0;
  cv::Point before_anchor(k, 0), after_anchor(0, 0);
  if (!along_x) {
    before_kernel = before_kernel.t();
    after_kernel = after_kernel.t();
    before_anchor = cv::Point(0, k);
  }
  cv::Mat low_before, low_after;
  cv::erode(grey, low_before, before_kernel, before_anchor);
  cv::erode(grey, low_after, after_kernel, after_anchor);
  // The tested pixels [k, n - k) and their neighbours one before and after.
  auto span = [&](const cv::Mat& m, int shift) {
    return along_x ? m.colRange(k + shift, n - k + shift) : m.rowRange(k + shift, n - k + shift);
  };
  const cv::Mat v = span(grey, 0);
  cv::Mat peak, test;
  cv::compare(v, span(grey, -1), peak, cv::CMP_GE);  // >= the one before, > the one after: a flat top counts once
  cv::compare(v, span(grey, 1), test, cv::CMP_GT);
  peak &= test;
  cv::Mat height;
  cv::subtract(v, span(low_before, 0), height);  // saturates at 0
  cv::compare(height, c, test, cv::CMP_GE);
  peak &= test;
  cv::subtract(v, span(low_after, 0), height);
  cv::compare(height, c, test, cv::CMP_GE);
  peak &= test;
  cv::Mat out = span(*ridges, 0);
  out |= peak;
}

}  // namespace

cv::Mat GridRidges(const cv::Mat& grey, int reach_px, double min_prominence_dn) {
  CV_Assert(grey.type() == CV_8UC1 && reach_px >= 1);
  // The grey levels are integers: a height >= c is one >= ceil(c).
  const int c = int(std::ceil(min_prominence_dn));
  cv::Mat ridges(grey.size(), CV_8UC1, cv::Scalar(0));
  OrRidgesAlong(grey, reach_px, c, true, &ridges);
  OrRidgesAlong(grey, reach_px, c, false, &ridges);
  ridges &= 1;
  return ridges;
}

int DropWithoutGridLine(const cv::Mat& left, const GridLineOptions& o, int reach_px, const cv::Rect& roi,
                        DisparityState* state) {
  if (!o.enabled || roi.area() == 0) return 0;
  // The ridges of the ROI and of what its windows reach, read with the
  // image around that (a ridge's test reaches reach_px further).
  const int r = o.radius_px;
  const cv::Rect image(0, 0, left.cols, left.rows);
  const cv::Rect window_area = cv::Rect(roi.x - r, roi.y - r, roi.width + 2 * r, roi.height + 2 * r) & image;
  const cv::Rect read_area = cv::Rect(window_area.x - reach_px, window_area.y - reach_px,
                                      window_area.width + 2 * reach_px, window_area.height + 2 * reach_px) &
                             image;
  const cv::Mat ridges = GridRidges(left(read_area), reach_px, o.min_prominence_dn);
  // Ridge pixels per window; outside the read area there are none.
  cv::Mat count;
  cv::boxFilter(ridges, count, CV_16U, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  int dropped = 0;
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const float* d = state->disparity_px.ptr<float>(y);
    const uint16_t* n = count.ptr<uint16_t>(y - read_area.y);  // column x at n[x - read_area.x]
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      if (!std::isfinite(d[x]) || n[x - read_area.x] >= o.min_ridge_px) continue;
      DropPoint(x, y, PixelStatus::kNoGridLine, state);
      ++dropped;
    }
  }
  return dropped;
}

}  // namespace stereorig
