// Where the line-index vernier (line_index.h) is read: pixels spread evenly
// over a component's footprint.
//
// The footprint is the component's valid pixels and the empty pixels up to
// gap_px along the row from them (an empty pixel reached from a valid pixel
// of the component on either side, with no valid pixel in between). Its
// valid pixels alone are a biased sample: they are the ones whose window
// passed the matcher's tests at the component's alignment, and at strong
// speckle those read the vernier nearer 0 on a wrong alignment than the
// footprint does (docs/reconstruct.md, "Strong speckle").
//
// The sample: list the footprint in raster order (index y * cols + x), N
// pixels; stride = max(1, N / samples); take the pixels at ranks
// floor(stride / 2 + j * stride) < N, the rank accumulated in a double as
// k += stride. An empty pixel starts from the valid pixel it is reached
// from (that pixel's disparity carried along its slope along the row); if
// reached from both sides, from the one listed first in the component's
// pixels.
//
// Found by scanning the component's bounding box (widened by gap_px) row by
// row, twice: once to count each row's footprint, once to pick the ranked
// pixels from the rows that hold them. Before, the whole footprint (up to
// 2 * gap_px + 1 times the component) was listed and stable-sorted, ~10 M
// instructions for a large component (callgrind, demo cup).
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace stereorig {

// A pixel of the sample and the disparity and slopes its refinement starts from.
struct FootprintStart {
  int i;    // y * cols + x
  float d;  // px: its own disparity; an empty pixel: its source's, carried along the row by slope_x
  float slope_x, slope_y;
  bool operator==(const FootprintStart&) const = default;
};

// Samples footprints of components of one disparity map. Holds a per-pixel
// scratch mark (4 bytes a pixel), so one sampler serves many components.
class FootprintSampler {
 public:
  // disparity_px, slope_x, slope_y: CV_32FC1, continuous, same size
  // (+inf disparity = empty). Held by reference: the maps may change between
  // calls (a moved or dropped component), each call reads them as they are.
  // gap_px >= 0; samples >= 1.
  FootprintSampler(const cv::Mat& disparity_px, const cv::Mat& slope_x, const cv::Mat& slope_y, int gap_px,
                   int samples);

  // Up to `samples` pixels of the footprint of `pixels` (indices y * cols + x,
  // no duplicates; entries whose disparity is empty now are not part of it,
  // but may be footprint gap pixels), in raster order. With
  // area_per_sample_px > 0, a footprint of N pixels gets
  // max(samples, floor(N / area_per_sample_px)) of them instead
  // (LineIndexOptions::area_per_sample_px), spread the same way.
  std::vector<FootprintStart> Sample(const std::vector<int>& pixels, int area_per_sample_px = 0);

 private:
  // Calls visit(i, source) for the footprint pixels of row y within columns
  // [x_begin, x_end], in order; source = i for a valid pixel, else the
  // valid pixel it starts from.
  template <typename Visit>
  void VisitRow(int y, int x_begin, int x_end, Visit&& visit) const;

  const cv::Mat& disparity_px_;
  const cv::Mat& slope_x_;
  const cv::Mat& slope_y_;
  const int cols_, gap_px_, samples_;
  // Per pixel: 1 + the position in `pixels` of a valid pixel of the
  // component being sampled, 0 elsewhere (cleared after each call).
  std::vector<int> order_;
  std::vector<int> row_count_;  // scratch: footprint pixels per row of the bounding box
};

}  // namespace stereorig
