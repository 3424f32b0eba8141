#include "reconstruct/region_grow.h"

#include <cmath>
#include <deque>

#include "calib/core/input_error.h"

namespace stereorig {

void GrowOptions::Check() const {
  if (!(max_deviation_px > 0 && max_deviation_px <= 4)) throw InputError("grow_max_deviation_px", "must be in (0, 4]");
}

int GrowDisparity(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const GrowOptions& o,
                  const RefineAcceptance& accept, DisparityState* state) {
  if (!o.enabled) return 0;
  cv::Mat& disparity = state->disparity_px;
  cv::Mat tried(left.size(), CV_8UC1, cv::Scalar(0));
  std::deque<cv::Point> queue;
  for (int y = roi.y; y < roi.y + roi.height; ++y)
    for (int x = roi.x; x < roi.x + roi.width; ++x)
      if (std::isfinite(disparity.at<float>(y, x))) queue.emplace_back(x, y);
  int added = 0;
  while (!queue.empty()) {
    const cv::Point p = queue.front();
    queue.pop_front();
    const float d = disparity.at<float>(p);
    const float gx = state->slope_x.at<float>(p), gy = state->slope_y.at<float>(p);
    const cv::Point next[4] = {{p.x - 1, p.y}, {p.x + 1, p.y}, {p.x, p.y - 1}, {p.x, p.y + 1}};
    for (const cv::Point& q : next) {
      if (!roi.contains(q) || std::isfinite(disparity.at<float>(q)) || tried.at<uint8_t>(q)) continue;
      tried.at<uint8_t>(q) = 1;
      const double predicted = d + gx * (q.x - p.x) + gy * (q.y - p.y);
      const SubpixelResult r = RefineDisparity(left, right, q.x, q.y, predicted, gx, gy, accept.subpixel);
      PixelStatus why = Accept(r, accept);
      if (why == PixelStatus::kPoint && std::abs(r.disparity_px - predicted) > o.max_deviation_px)
        why = PixelStatus::kOffPlane;
      if (why != PixelStatus::kPoint) continue;  // keeps the status of its first rejection
      disparity.at<float>(q) = float(r.disparity_px);
      state->confidence.at<float>(q) = float(std::clamp(r.zncc, 0.0, 1.0));
      state->status.at<uint8_t>(q) = uint8_t(PixelStatus::kPoint);
      state->slope_x.at<float>(q) = gx;
      state->slope_y.at<float>(q) = gy;
      queue.push_back(q);
      ++added;
    }
  }
  return added;
}

}  // namespace stereorig
