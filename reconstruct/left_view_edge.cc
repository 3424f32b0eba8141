#include "reconstruct/left_view_edge.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

int DropLeftViewEdge(const cv::Mat& left_valid, int half_width_px, int half_height_px, const cv::Rect& roi,
                     DisparityState* state) {
  if (left_valid.empty()) return 0;
  const cv::Mat& disparity = state->disparity_px;
  STEREORIG_CHECK(left_valid.type() == CV_8UC1 && left_valid.size() == disparity.size());
  STEREORIG_CHECK(half_width_px >= 0 && half_height_px >= 0);
  // A pixel's window is all data where the mask eroded by the window is
  // set; the image's own border counts as no data (BORDER_CONSTANT 0).
  cv::Mat inside;
  cv::erode(left_valid, inside,
            cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * half_width_px + 1, 2 * half_height_px + 1)),
            cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  int dropped = 0;
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const uint8_t* in = inside.ptr<uint8_t>(y);
    const float* d = disparity.ptr<float>(y);
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      if (in[x] || !std::isfinite(d[x])) continue;
      DropPoint(x, y, PixelStatus::kLeftViewEdge, state);
      ++dropped;
    }
  }
  return dropped;
}

}  // namespace stereorig
