// The runtime options tied to the laser grid's period P along the rows
// (grid_period.h measures it), set from P by the rules of
// docs/reconstruct.md "Another projector: a different grid period". The
// defaults are these rules at the default grid's P = 8 px, so a measured P
// that rounds to 8 px leaves every key at its default.
//
// P is taken to the nearest whole pixel: the keys are whole pixels (or,
// grid_half_period_px, half pixels), and the defaults were tuned on the
// simulator's default grid, which reads 8.07-8.46 px on its scenes
// (docs/reconstruct.md), so no finer step has been shown to matter.
#pragma once

#include <string>
#include <vector>

#include "reconstruct/matcher.h"

namespace stereorig {

// The periods the rules below can serve, px: 1.5 P must fit
// line_index_max_shift_px's limit of 64; below 3 px the lines (~2.6 px
// wide at half height on the default rig, sigma ~1.1 px) merge, and the
// grid is no longer resolved.
inline constexpr double kMinGridPeriodPx = 3;
inline constexpr double kMaxGridPeriodPx = 42;

// The row offset per period the line index's vernier reads between a
// component on its line and one a period off (RowOffsetPerPeriodPx,
// grid_period.h), as the default thresholds need it (line_index.h): above
// the 0.15 px at which a component is dropped as a period off, by the
// ~0.05 px standard error of a component's reading at strong speckle (a
// period-off component read one standard error low is still dropped);
// below the 1 px row offset the sub-pixel fit allows (subpixel_refine.h),
// by twice that. The default rig reads 0.26-0.46 px on the simulator's
// plates (its modules' rolls turn the grid 1.8-3.2 deg in the rectified
// images). Not a key: the projector's turn about its axis sets it.
inline constexpr double kMinRowOffsetPerPeriodPx = 0.2;
inline constexpr double kMaxRowOffsetPerPeriodPx = 0.9;

struct GridPeriodKey {
  std::string key;  // as the options file names it: match.<key>
  double value = 0;
  double before = 0;  // the options' value before the change
};

// Sets the keys tied to the period in *o and returns them, each with its
// value before. Throws InputError("period") if period_px is outside
// [kMinGridPeriodPx, kMaxGridPeriodPx].
//  - grid_half_period_px = P / 2 (the distinctness shift, the grid-line
//    test's ridge reach, the right view's edge zone);
//  - line_index_max_shift_px = 1.5 P (the next alignment, stretched by a
//    surface turned away, stays within the shifts tried);
//  - line_index_window_half_height_px = at least (P - 1) / 2, never below
//    the default (the vernier's window holds a near-horizontal line);
//  - line_index_footprint_gap_px = P, at most 16 (its limit: one period of
//    empty pixels between the lines belongs to the footprint);
//  - grid_line_radius_px = ceil(P / 2) + 1 (inside the grid's envelope
//    every pixel is within half a period of a line).
std::vector<GridPeriodKey> SetGridPeriodKeys(double period_px, MatchOptions* o);

}  // namespace stereorig
