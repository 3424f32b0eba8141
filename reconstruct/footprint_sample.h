// Where the line-index vernier (line_index.h) is read: pixels of a
// component's footprint, on a lattice fixed in the image (SampleLattice,
// SampleLatticeAtLeast: the default since session 10) or spread evenly by
// raster rank (Sample).
//
// The footprint is the component's valid pixels and the empty pixels up to
// gap_px along the row from them (an empty pixel reached from a valid pixel
// of the component on either side, with no valid pixel in between). Its
// valid pixels alone are a biased sample: they are the ones whose window
// passed the matcher's tests at the component's alignment, and at strong
// speckle those read the vernier nearer 0 on a wrong alignment than the
// footprint does (docs/reconstruct-log.md, "Strong speckle").
//
// The raster-rank sample: list the footprint in raster order (index y * cols + x), N
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

// Every `every`-th of `sample` (every >= 1) by rank: the elements at
// floor(every / 2 + j * every), the position accumulated in a double.
std::vector<FootprintStart> ThinByRank(const std::vector<FootprintStart>& sample, double every);

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

  // The footprint pixels of `pixels` on the image's lattice of pitch
  // pitch_px: x and y both = pitch_px / 2 (mod pitch_px), in raster order.
  // The lattice is fixed in the image, not in the component, so two nearly
  // equal components (one surface matched with slightly different options)
  // are read at nearly the same pixels, and their readings differ only by
  // the pixels that differ; the raster-rank Sample moves nearly every
  // sample when a component gains or loses a few pixels. At pitch_px >= the
  // vernier's 9 px window the samples' windows do not overlap.
  std::vector<FootprintStart> SampleLattice(const std::vector<int>& pixels, int pitch_px);

  // SampleLattice with at least min_samples pixels: at the coarsest pitch p
  // of LatticePitchesPx() with N >= min_samples * p^2 (N = pixels.size(): its
  // valid pixels hold about N / p^2 lattice points), or finer while that
  // gives fewer, down to 1 px (every footprint pixel): a thin component can
  // miss a coarse lattice entirely. A ladder, not sqrt(N / min_samples)
  // rounded, so that a component's pitch changes only where its size
  // crosses one of few thresholds. At kDensePitchPx or finer (components
  // of less than ~9 x min_samples px, or thin ones), at most
  // 2 x min_samples, every k-th of the lattice's in raster order: their
  // 9-px windows overlap by 7/9 or more, so more samples cost more and read
  // little more (with the probe in line_index.cc: the line index's time on
  // the 5 demo scenes ~+30 % without them). That rank brings back some
  // order dependence for these small components: a choice by a hash of the
  // position was measured and read the demo ball bar's module 0 with std
  // 0.072 mm instead of 0.068 (both draws of small pieces). pitch_px: if
  // not null, receives the pitch used.
  std::vector<FootprintStart> SampleLatticeAtLeast(const std::vector<int>& pixels, int min_samples,
                                                   int* pitch_px = nullptr);

  // The lattice pitches, finest first: 1, 2, 3, 4, 6, then 9 and 12 px
  // times powers of 2, up to the image's larger side.
  std::vector<int> LatticePitchesPx() const;
  static constexpr int kDensePitchPx = 2;

 private:
  // Calls visit(i, source) for the footprint pixels of row y within columns
  // [x_begin, x_end], in order; source = i for a valid pixel, else the
  // valid pixel it starts from.
  template <typename Visit>
  void VisitRow(int y, int x_begin, int x_end, Visit&& visit) const;

  // Marks the valid pixels of `pixels` in order_ and finds their bounding
  // box widened by gap_px along the rows; false if none is valid.
  bool Mark(const std::vector<int>& pixels, int* x_begin, int* x_end, int* y_min, int* y_max);
  void Unmark(const std::vector<int>& pixels);
  // The start of footprint pixel i reached from valid pixel `source`.
  FootprintStart StartAt(int i, int source) const;

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
