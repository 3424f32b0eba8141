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

// grid_half_period_px is P / 2 up to this, px, and this above it. It is the
// distinctness test's shift (disparity_state.h): a match must correlate
// better than its window moved this far either side. Past the lines' own
// width (~2.6 px at half height on the default rig) a longer shift does not
// decorrelate a true match any better; it only takes the probes further
// off, and at a rim onto the background, so that a mismatch there passes.
// Measured (docs/reconstruct-log.md, session 32) on a 34-line grating, P =
// 12.7-13.0 px, six datasets (lines of sigma 1 and 2 mrad, three seeds
// each), tune's keys with P / 2 = 6.5 px against the same with 4 px: the
// ball bar's std rose on 11 of the 12 modules (0.11-0.21 mm, against
// 0.08-0.13 mm), for more fill on the cup (+1-5 points); with 4 px it stayed
// within 0.02 mm of the defaults' on 11 of the 12 (the 12th took a patch a
// line off, the line index's). So coarser grids keep the default grid's
// half period.
inline constexpr double kMaxGridHalfPeriodPx = 4;

// The widest lines, sigma / P along the rows (grid_line_width.h), the
// runtime's defaults are known to work with. The simulator's default grid
// reads 0.168 on its plate (both modules; 0.171-0.173 on the cup), a
// 34-line grating 0.108 (the per-module std over 0.1 mm on 2 of 18
// scene-modules, three seeds). Lines twice as wide (line_sigma_mrad 2) read
// 0.177-0.181 on the 34-line grating (std over 0.1 mm on 7 of 18, up to
// 0.185 mm), and 0.227 on the default 51-line grating, where modules lost
// most of their points (sphere module 1 0 % fill, ball bar 2.4 %) or kept
// a patch a line off (0.52 mm std) (docs/reconstruct-log.md, session 32).
inline constexpr double kMaxLineSigmaOverPeriod = 0.18;

struct GridPeriodKey {
  std::string key;  // as the options file names it: match.<key>
  double value = 0;
  double before = 0;  // the options' value before the change
  // The rule's value where it was not applied (value is then `before`), 0
  // where it was: printed as a suggestion, to be verified by hand.
  double rule_not_applied = 0;
};

// Sets the keys tied to the period in *o and returns them, each with its
// value before. Throws InputError("period") if period_px is outside
// [kMinGridPeriodPx, kMaxGridPeriodPx].
//  - grid_half_period_px = P / 2, at most kMaxGridHalfPeriodPx (the
//    distinctness shift, the grid-line test's ridge reach, the right
//    view's edge zone);
//  - line_index_max_shift_px = 1.5 P (the next alignment, stretched by a
//    surface turned away, stays within the shifts tried);
//  - line_index_window_half_height_px = at least (P - 1) / 2, never below
//    the default (the vernier's window holds a near-horizontal line);
//  - line_index_footprint_gap_px = P, at most 16 (its limit: one period of
//    empty pixels between the lines belongs to the footprint);
//  - grid_line_radius_px = ceil(P / 2) + 1 (inside the grid's envelope
//    every pixel is within half a period of a line), but only where that
//    does not widen it: a wider window also keeps matches on an object's
//    outline beyond the envelope. docs/reconstruct.md widens it only where
//    the grid-line test (no_grid_line) takes a visible share of the lit
//    pixels, and that share, read on the plate tune measures, did not tell
//    where widening helps: 0.01-0.03 % of the lit pixels per module on a
//    34-line grating (seeds 1 and 2), where the rule's 7-8 px gained fill at
//    the same std, against 0.23-1.99 % on a 3-module ring (P 11.4 px), where
//    its 7 px raised a ball bar's std from 0.20 to 0.26 mm (session 49). So
//    a wider value is left as rule_not_applied, the current one kept
//    (docs/reconstruct.md, "Another projector", step 2).
std::vector<GridPeriodKey> SetGridPeriodKeys(double period_px, MatchOptions* o);

// How near a measured period may lie to a half pixel, px, before another
// capture of the same rig may round it the other way: the period read on
// one rig varies by a few per cent with the surface's depth and turn (the
// default grid: 8.07 px on the plate, 8.46 on the tuber; a 34-line grating
// 12.46 on the cup, 12.74 on the plate), ~0.1 px between plate positions.
inline constexpr double kRoundingMarginPx = 0.1;

// The whole-pixel period on the other side of the half pixel period_px
// lies within kRoundingMarginPx of (e.g. 12 for 12.55, 13 for 12.45), or 0
// if it lies further from one: the keys SetGridPeriodKeys sets may then
// differ between two captures of one rig.
int OtherRoundedPeriodPx(double period_px);

}  // namespace stereorig
