// Chessboard corners as OpenCV finds them: a rectangular grid in OpenCV's own
// order, refined to sub-pixel precision. Which corner of the target each one
// is gets decided later (detect.h), from the tags or the square colours.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace stereorig {

struct ChessboardGridOptions {
  // cv::findChessboardCornersSB's exhaustive search: finds boards in more
  // views (steep tilts, blur) for ~20% more time. Default true.
  bool exhaustive = true;
  // cv::findChessboardCornersSB's CALIB_CB_ACCURACY (upsampled search).
  // Default false: measured on 20 rendered views of the default target it is
  // ~2x slower and, once cornerSubPix refines the corners, no more accurate
  // (0.031 vs 0.031 px RMS; docs/targets.md).
  bool upsample = false;
  // Refine each corner with cv::cornerSubPix in a window of half-size
  // refine_window_fraction x (distance to its nearest neighbour corner),
  // clamped to [refine_min_half_px, refine_max_half_px]. Default true.
  // Measured: 0.064 px RMS (SB alone) -> 0.031 px (refined) on 20 views.
  bool refine = true;
  double refine_window_fraction = 0.4;  // of the local corner spacing; default 0.4
  int refine_min_half_px = 2;           // default 2
  int refine_max_half_px = 16;          // default 16
  // Near the image's edge the window shrinks to stay inside; a corner whose
  // window would be smaller than this fraction of the spacing is dropped
  // (measured on the simulator's images: a corner 6 px from the edge, refined
  // in a 3 px window, was 3.5 px off). Default 0.25.
  double refine_min_window_fraction = 0.25;
  // A refinement that moves a corner further than this fraction of the local
  // corner spacing has slid off it; the corner is dropped. Default 0.25
  // (OpenCV's own estimate is off by up to ~1 px on small, steeply tilted
  // squares, where cornerSubPix is right).
  double refine_max_shift_fraction = 0.25;
  void Check() const;  // throws InputError naming the bad field
};

// A grid of `cols` x `rows` corners in OpenCV's order (row-major: q_px[r *
// cols + c]), pixels in mrcal's convention ((0,0) = centre of the top-left
// pixel; OpenCV's corner coordinates already use it - measured, see
// detect_test.cc).
struct ChessboardGrid {
  int cols = 0;
  int rows = 0;
  std::vector<Eigen::Vector2d> q_px;  // (rows * cols)
  std::vector<bool> usable;           // (rows * cols) false: dropped by the refinement
  int num_dropped = 0;                // corners the refinement dropped
  const Eigen::Vector2d& at(int c, int r) const { return q_px[r * cols + c]; }
};

// Finds a chessboard in `grey` (CV_8UC1). If `partial`, any grid of at least
// `min_size` corners each way is accepted (CALIB_CB_LARGER; the board may run
// out of the image); else exactly `size` (cols x rows, either way round).
// Returns false if none was found.
bool FindChessboardGrid(const cv::Mat& grey, cv::Size size, bool partial, const ChessboardGridOptions& options,
                        ChessboardGrid* grid);

// The cornerSubPix half-window for a corner at `q_px` whose nearest
// neighbour is `spacing_px` away: options' fraction of the spacing, clamped
// to [min, max] and shrunk so that the window stays 2 px inside the image;
// -1 if what is left is below refine_min_window_fraction of the spacing or
// refine_min_half_px.
int RefineHalfWindow(const ChessboardGridOptions& options, double spacing_px, const Eigen::Vector2d& q_px,
                     const cv::Size& image_size);

// OpenCV's cv::estimateChessboardSharpness on a found grid: the mean width
// (px) of the 10%-90% black-to-white rise across the squares' edges (sharp is
// below ~3 px), and the mean black and white levels (DN).
struct ChessboardSharpness {
  double edge_rise_px = 0;
  double black_dn = 0;
  double white_dn = 0;
};
ChessboardSharpness MeasureSharpness(const cv::Mat& grey, const ChessboardGrid& grid);

}  // namespace stereorig
