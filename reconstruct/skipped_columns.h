// The matcher's first sub-pixel pass on every column_step-th column only
// (MatchOptions::subpixel_column_step), the pixels between taking their
// disparity from the refined pixels either side on their row.
//
// Why this is sound: a pixel's Lucas-Kanade window (9x3 by default) lies
// inside the union of its refined neighbours' windows, a column or two
// away, so its own estimate would carry nearly the same laser speckle as
// theirs (the refined disparities' errors correlate 0.88 at 1 px along the
// row, ~0 only beyond ~8 px: local_surface_fit.h). The surface fit after
// it averages over 21x11 pixels, i.e. over a few correlation lengths, so
// refining every pixel adds little independent information to it.
// Why it stays honest: a skipped pixel is interpolated only between two
// refined pixels on its row that both passed every test (ZNCC, texture,
// distinctness, range, the local plane), i.e. only inside a measured and
// accepted stretch, never beyond its end; and only where the two agree with
// the local disparity slope (a depth edge or a grid-period step between them
// fails). The interpolated value must then pass the pixel's own local-plane
// test. Every other skipped pixel is refined and tested on its own, exactly
// as with column_step 1, so the edges of the accepted regions, and the fill
// there, are those of the full pass.
#pragma once

#include <cstdint>

namespace stereorig {

// The largest difference of the two refined neighbours from the line the
// local disparity slope predicts between them, px, for a skipped pixel to
// be interpolated: about four times the scatter of that difference on the
// demo captures (two estimates 2 px apart: 0.27 px each, correlated ~0.9),
// a sixteenth of the laser grid's ~8 px period (a wrong-line neighbour is a
// period off).
constexpr double kMaxSkippedColumnJumpPx = 0.5;

// True if the pixel at column offset xx from the region's first column is
// refined (the first column, and every column_step-th after it).
inline bool IsRefinedColumn(int xx, int column_step) { return xx % column_step == 0; }

// Row arrays of the disparity state (disparity_state.h), indexed by image
// column: the interpolated disparity and confidence of skipped pixel x
// between the refined pixels x_left < x < x_right, if both are points
// (PixelStatus::kPoint) that differ from the line slope_x (px/px) predicts
// by at most kMaxSkippedColumnJumpPx. The confidence is the lower of the
// two (the pixel's window correlates about as they do). False: refine x.
bool InterpolateSkippedColumn(const float* disparity_px, const float* confidence, const uint8_t* status, int x_left,
                              int x, int x_right, double slope_x, double* d_px, float* confidence_out);

}  // namespace stereorig
