// The laser grid's period P along the rows of a rectified left image,
// measured from the image itself: the distance between neighbouring
// near-vertical lines that several runtime options are tied to
// (grid_period_options.h, docs/reconstruct.md "Another projector").
//
// Along a row of a grid-lit surface the grey level is a train of line
// profiles P apart, so its autocorrelation peaks at lags P, 2P, 3P, ...
// Per block of rows, the autocorrelation of the lit runs' central
// differences is summed over the block's rows and normalised by its value
// at lag 0. Differences, not grey levels: what varies slowly along a row
// (shading, albedo, and the other family's lines, which cross a row at a
// few degrees as bumps tens of px wide) would add a broad correlation that
// tilts the peaks (0.06-0.14 px at 8 px and 10 degrees, on grey levels).
// The block's period is the least-squares fit of m P to the positions of
// its first peaks (each from a parabola through the logarithms of its
// three lags): the m-th peak fixes P m times more tightly than the first,
// and a curved surface's spread of periods washes out the later peaks
// first, so only the clear ones count. The image's period is the median
// over the blocks, its spread half their interquartile range: a surface
// turned towards or away from the camera stretches the period by the
// foreshortening, so the spread says whether the surface was flat and
// facing enough to measure on.
#pragma once

#include <limits>
#include <opencv2/core.hpp>
#include <optional>

namespace stereorig {

struct GridPeriodOptions {
  int block_rows = 16;     // rows summed per block, px
  int min_run_px = 48;     // shortest lit run along a row that is used, px (six periods of the default grid)
  int max_period_px = 42;  // longest period looked for, px (the runtime's keys allow up to ~42: grid_period_options.h)
  double min_peak = 0.2;   // a peak's normalised autocorrelation must reach this...
  double min_peak_dip = 0.2;  // ...and rise this far above the lowest value at smaller lags (a real dip between lines)
  int min_blocks = 3;         // blocks that must give a period
};

struct GridPeriodMeasurement {
  double period_px = 0;  // the median of the blocks' periods, px along the rows
  double spread_px = 0;  // half the interquartile range of the blocks' periods, px
  int blocks = 0;        // blocks that gave a period
  int rows = 0;          // rows with at least one lit run of min_run_px
  // How far the near-vertical lines move along the row from one row to the
  // next, px (the tangent of the grid's turn against the rows, its sign the
  // direction): the median of the blocks' readings, each from the cross-
  // correlations of rows 4, 8, .., 32 apart, their peaks fitted through the
  // origin (grid_period.cc). NaN where fewer than min_blocks blocks read
  // it.
  double shift_per_row_px = std::numeric_limits<double>::quiet_NaN();
  // The lines' width for their period, sigma / P along the rows
  // (grid_line_width.h), from the harmonics of the blocks' runs at each
  // block's own period. NaN below kMinLineWidthPeriodPx or where the
  // second harmonic does not stand above the noise.
  double line_sigma_over_period = std::numeric_limits<double>::quiet_NaN();
};

// The grid's turn against the rows, degrees (>= 0): atan |shift_per_row_px|.
double GridTurnDeg(const GridPeriodMeasurement& m);
// The row offset between neighbouring lines one period apart along a row,
// P |tan(turn)|, px: what the line index's vernier reads
// (line_index.h; it must stay well above its 0.15 px drop threshold and
// below the 1 px the sub-pixel fit's row offset allows).
double RowOffsetPerPeriodPx(const GridPeriodMeasurement& m);

// left: CV_8UC1, the rectified left image (or a view of it). lit: CV_8UC1
// of left's size, non-zero where the grid lights the pixel (lit_mask.h);
// runs are taken along each row between gaps longer than max_period_px, so
// the dark centres of a long period's cells do not cut them. Returns
// nothing where fewer than min_blocks blocks show a periodic grid (no
// grid, passive light, or too few lit rows).
std::optional<GridPeriodMeasurement> MeasureGridPeriodPx(const cv::Mat& left, const cv::Mat& lit,
                                                         const GridPeriodOptions& o = {});

}  // namespace stereorig
