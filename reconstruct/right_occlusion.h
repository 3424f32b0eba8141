// Which left pixels the right camera cannot see, read from the disparity map
// itself (x_right = x_left - d on the same rectified row), and dropping them.
//
// A left pixel the right camera does not see has no true match, yet SGM and
// growing give it one: the laser line one period over (+3.5 mm at 200 mm),
// or the edge of the zero-filled border. Two cases:
//   - occluded: a nearer surface lands at or over the same right column. On
//     one row, left pixel x with disparity d lands at x - d; a pixel x' > x
//     that is nearer by more than 1 px and lands at x' - d' <= x - d hides
//     it. A smooth surface's own pixels land in order (x' - d' > x - d while
//     the right view does not fold it, dd/dx < 1), so it does not hide
//     itself; the 1 px step keeps disparity noise (~0.25 px) on a steep flank
//     from swapping neighbours' order into an occlusion. At a depth step of
//     D px the zone dropped is the D px left of the nearer surface's edge.
//     No margin here: widening the zone by 1 px cost 0.7 % of the demo
//     cup's truth fill (module 1) and changed no accuracy figure.
//   - outside the right view: a right column from floor(x - d - margin_px)
//     to floor(x - d + margin_px) has no data (`right_valid` is 0 there: the
//     rectified right image's pixels that map outside the sensor, or outside
//     the image). The margin keeps matches that straddle the edge of the
//     zero fill out.
// Neither should cost truth fill (fill_score.h counts only pixels both
// cameras see) beyond the margin's pixels at the right view's edge.
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"

namespace stereorig {

// CV_8UC1, map_x's size: 255 where the rectified pixel samples the sensor
// (map_x in [0, width - 1], map_y in [0, height - 1]), else 0. map_x, map_y:
// CV_32FC1 rectification maps (rectified -> original px) of either view: the
// right view's for the test below, the left view's for left_view_edge.h.
cv::Mat ViewValidMask(const cv::Mat& map_x, const cv::Mat& map_y, const cv::Size& sensor_size);

// The right view's columns without data, row by row, for the tests that
// ask whether a range of right columns holds one (this one's edge test,
// right_view_edge.h): built once per capture, each question is then one
// difference of per-row counts.
class ViewGaps {
 public:
  // valid: CV_8UC1 (ViewValidMask), or empty: every column of the image has
  // data (only the image's own edges bound the view).
  explicit ViewGaps(const cv::Mat& valid);
  // Whether columns first..last of row y (0 <= first <= last < the mask's
  // width) hold one without data. Always false without a mask.
  bool AnyIn(int y, int first, int last) const {
    if (invalid_before_.empty()) return false;
    const int* row = invalid_before_.ptr<int>(y);
    return row[last + 1] > row[first];
  }
  bool empty() const { return invalid_before_.empty(); }
  cv::Size size() const { return {invalid_before_.cols - 1, invalid_before_.rows}; }

 private:
  cv::Mat invalid_before_;  // CV_32SC1, rows x (cols + 1): a row's columns without data left of column c
};

// Sets the disparity of every pixel of `roi` that the right camera cannot
// see (see above) to +inf, its confidence to 0 and its status to
// PixelStatus::kOccluded. margin_px: the right-view edge's margin, > 0
// (0 = both tests off, nothing is touched).
// right_valid: CV_8UC1 the disparity map's size, or empty (every column of
// the image is valid). Returns the number of pixels dropped. The rows are
// independent: they run on up to num_threads threads (ParallelForChunks),
// with the same result on any number.
int DropRightInvisible(double margin_px, const cv::Mat& right_valid, const cv::Rect& roi, DisparityState* state,
                       int num_threads = 1);
// The same with the right view's gaps already counted (ViewGaps of that
// mask; empty: none).
int DropRightInvisible(double margin_px, const ViewGaps& right_gaps, const cv::Rect& roi, DisparityState* state,
                       int num_threads = 1);

}  // namespace stereorig
