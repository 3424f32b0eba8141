#include "reconstruct/right_occlusion.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/parallel_for.h"

namespace stereorig {

cv::Mat ViewValidMask(const cv::Mat& map_x, const cv::Mat& map_y, const cv::Size& sensor_size) {
  STEREORIG_CHECK(map_x.type() == CV_32FC1 && map_y.type() == CV_32FC1 && map_x.size() == map_y.size());
  cv::Mat valid(map_x.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < valid.rows; ++y) {
    const float* mx = map_x.ptr<float>(y);
    const float* my = map_y.ptr<float>(y);
    uint8_t* v = valid.ptr<uint8_t>(y);
    for (int x = 0; x < valid.cols; ++x)
      v[x] = mx[x] >= 0 && my[x] >= 0 && mx[x] <= sensor_size.width - 1 && my[x] <= sensor_size.height - 1 ? 255 : 0;
  }
  return valid;
}

ViewGaps::ViewGaps(const cv::Mat& valid) {
  if (valid.empty()) return;
  STEREORIG_CHECK(valid.type() == CV_8UC1);
  invalid_before_ = cv::Mat(valid.rows, valid.cols + 1, CV_32SC1);
  for (int y = 0; y < valid.rows; ++y) {
    const uint8_t* v = valid.ptr<uint8_t>(y);
    int* count = invalid_before_.ptr<int>(y);
    count[0] = 0;
    for (int c = 0; c < valid.cols; ++c) count[c + 1] = count[c] + (v[c] == 0);
  }
}

int DropRightInvisible(double margin_px, const cv::Mat& right_valid, const cv::Rect& roi, DisparityState* state,
                       int num_threads) {
  if (!(margin_px > 0)) return 0;
  return DropRightInvisible(margin_px, ViewGaps(right_valid), roi, state, num_threads);
}

int DropRightInvisible(double margin_px, const ViewGaps& right_gaps, const cv::Rect& roi, DisparityState* state,
                       int num_threads) {
  if (!(margin_px > 0)) return 0;
  const cv::Mat& disparity = state->disparity_px;
  STEREORIG_CHECK(right_gaps.empty() || right_gaps.size() == disparity.size());
  const int cols = disparity.cols;
  constexpr double kStepPx = 1;  // how much nearer an occluder must be (header)
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::atomic<int> dropped{0};
  // Each row reads and drops only its own pixels.
  ParallelForChunks(roi.height, num_threads, [&](int begin, int end) {
    std::vector<int> drop;
    // first_landing[i]: the leftmost right column x' - d' that a valid pixel
    // x' >= roi.x + i of the row lands at (+inf: none). A pixel can only be
    // occluded if a pixel right of it lands at or left of its own landing, so
    // where first_landing[i + 1] > xr the scan below is skipped: on a surface
    // the right view does not fold, that is nearly every pixel, and the scan
    // (up to row_max - d px) was the filter's cost. The same float landings
    // as the scan's, so the result is the same.
    std::vector<float> first_landing(roi.width + 1);
    // The edge test below asks whether any column of a short range has no
    // data; one difference of ViewGaps' per-row counts answers it, where
    // testing the columns one by one was a third of the filter's cost.
    for (int y = roi.y + begin; y < roi.y + end; ++y) {
      const float* d = disparity.ptr<float>(y);
      float row_max = -kInf;
      first_landing[roi.width] = kInf;
      for (int x = roi.x + roi.width - 1; x >= roi.x; --x) {
        const bool ok = std::isfinite(d[x]);
        if (ok) row_max = std::max(row_max, d[x]);
        first_landing[x - roi.x] = ok ? std::min(first_landing[x - roi.x + 1], x - d[x]) : first_landing[x - roi.x + 1];
      }
      drop.clear();
      for (int x = roi.x; x < roi.x + roi.width; ++x) {
        if (!std::isfinite(d[x])) continue;
        const double xr = x - d[x];
        // Outside the right view: a column from c_first to c_last (c_first <=
        // c_last, as margin_px > 0) outside the image, or one without data.
        const int c_first = int(std::floor(xr - margin_px)), c_last = int(std::floor(xr + margin_px));
        bool hidden = c_first < 0 || c_last >= cols || right_gaps.AnyIn(y, c_first, c_last);
        // Occluded: an occluder x' lands at x' - d' <= xr, so
        // x' <= x + (d' - d) <= x + (row_max - d).
        if (!hidden && first_landing[x - roi.x + 1] <= xr) {
          const int last = std::min(roi.x + roi.width - 1, int(std::floor(x + row_max - d[x])));
          for (int xo = x + 1; xo <= last && !hidden; ++xo)
            hidden = std::isfinite(d[xo]) && d[xo] > d[x] + kStepPx && xo - d[xo] <= xr;
        }
        if (hidden) drop.push_back(x);
      }
      // After the row's test: a dropped pixel still hides those behind it.
      for (int x : drop) DropPoint(x, y, PixelStatus::kOccluded, state);
      dropped += int(drop.size());
    }
  });
  return dropped.load();
}

}  // namespace stereorig
