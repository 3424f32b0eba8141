#include "reconstruct/right_view_edge.h"

#include <cmath>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

int DropUnverifiableAtRightViewEdge(const cv::Mat& right_valid, const RefineAcceptance& accept, double max_step_px,
                                    const cv::Rect& roi, DisparityState* state) {
  return DropUnverifiableAtRightViewEdge(ViewGaps(right_valid), accept, max_step_px, roi, state);
}

int DropUnverifiableAtRightViewEdge(const ViewGaps& right_gaps, const RefineAcceptance& accept, double max_step_px,
                                    const cv::Rect& roi, DisparityState* state) {
  const cv::Mat& disparity = state->disparity_px;
  STEREORIG_CHECK(right_gaps.empty() || right_gaps.size() == disparity.size());
  STEREORIG_CHECK(max_step_px > 0 && (roi & cv::Rect(0, 0, disparity.cols, disparity.rows)) == roi);
  const int cols = disparity.cols;
  const double half_width_px = accept.subpixel.half_width_px;
  // The zone, over the ROI: 1 = a valid pixel whose alternatives a period
  // either side reach a right column without data.
  cv::Mat zone(roi.size(), CV_8UC1, cv::Scalar(0));
  int in_zone = 0;
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const float* d = disparity.ptr<float>(y);
    const float* slope_x = state->slope_x.ptr<float>(y);
    uint8_t* z = zone.ptr<uint8_t>(y - roi.y);
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      if (!std::isfinite(d[x])) continue;
      const double slope = std::isfinite(slope_x[x]) ? slope_x[x] : 0.0;
      const double reach = 2 * DistinctnessShiftPx(slope, accept) + half_width_px;
      const double xr = x - d[x];
      const int c_first = int(std::floor(xr - reach)), c_last = int(std::ceil(xr + reach));
      const bool unverifiable = c_first < 0 || c_last >= cols || right_gaps.AnyIn(y, c_first, c_last);
      if (unverifiable) {
        z[x - roi.x] = 1;
        ++in_zone;
      }
    }
  }
  if (in_zone == 0) return 0;
  // The zone's components; one that touches a pixel of its surface outside
  // the zone is kept, the rest dropped.
  cv::Mat seen(roi.size(), CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> stack, component;
  int dropped = 0;
  auto joined = [&](const cv::Point& a, const cv::Point& b) {  // b inside roi, both in ROI coordinates
    const float da = disparity.at<float>(a.y + roi.y, a.x + roi.x), db = disparity.at<float>(b.y + roi.y, b.x + roi.x);
    return std::isfinite(db) && std::abs(db - da) <= max_step_px;
  };
  for (int y = 0; y < roi.height; ++y)
    for (int x = 0; x < roi.width; ++x) {
      if (!zone.at<uint8_t>(y, x) || seen.at<uint8_t>(y, x)) continue;
      bool leaves_zone = false;
      component.clear();
      stack.assign(1, cv::Point(x, y));
      seen.at<uint8_t>(y, x) = 1;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        component.push_back(p);
        const cv::Point neighbours[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
        for (const cv::Point& n : neighbours) {
          if (n.x < 0 || n.y < 0 || n.x >= roi.width || n.y >= roi.height || !joined(p, n)) continue;
          if (!zone.at<uint8_t>(n)) {
            leaves_zone = true;
          } else if (!seen.at<uint8_t>(n)) {
            seen.at<uint8_t>(n) = 1;
            stack.push_back(n);
          }
        }
      }
      if (leaves_zone) continue;
      for (const cv::Point& p : component) DropPoint(p.x + roi.x, p.y + roi.y, PixelStatus::kRightViewEdge, state);
      dropped += int(component.size());
    }
  return dropped;
}

}  // namespace stereorig
