// A module's row drift: how far its rectified rows are off, read from the
// laser grid's vernier (line_index.h) at no extra cost.
//
// The line index tells the grid's lines apart by a row offset of ~0.36 px
// per period (8 px x tan 2.6 deg) and keeps a component that reads within
// max_row_offset_px (0.1 px) of 0. That is a tolerance on the calibration
// too: a camera turned by 0.011 deg since calibration (0.2 px of rows at
// f = 1025 px) makes every correct match read 0.2 px, past about half a
// period's step, and the line index then puts whole surfaces one period off
// (~2-3.5 mm at 200 mm), often with the fill still high, or drops most of
// the module. Measured on the demo's cup, module 0's right camera turned
// about its x axis: mean |error| 0.035 mm at 0.1 px, 0.037 mm at 0.15 px,
// 2.17 mm at 0.2 px and 2.15 mm at 0.5 px (docs/reconstruct-log.md,
// "Session 47"). The components the line index kept or moved read the
// module's row offset while it is under ~0.2 px: an early warning of a drift
// that grows. Not a guard against a module already broken: past ~0.2 px the
// reading wraps (the vernier cannot tell a drift of s from one of s - 0.36
// px) and reads small on most scenes; a roll reads ~0 at the image's centre;
// a turn that moves columns reads nothing (docs/reconstruct.md, "Row
// drift"; the nightly check is that guard).
#pragma once

#include <span>

#include "reconstruct/line_index.h"

namespace stereorig {

struct RowDrift {
  bool read = false;               // some component gave a reading
  double row_offset_px = 0;        // the pixel-weighted median reading (MeanRowDrift: the readings' mean)
  double standard_error_px = 0;    // that reading's own standard error
  int components = 0, pixels = 0;  // the readings it is over
  int captures = 0;                // the captures it is over: 1, or MeanRowDrift's count
  bool warned = false;             // RowDriftWarned, as the runtime's options set it
};

// The pixel-weighted median of the components' readings (the reading
// covering the middle pixel when they are sorted by offset): one large
// surface decides, a few small wrong components do not.
RowDrift ReadRowDrift(std::span<const VernierReading> readings);

// The mean of several captures' drifts (those read), with the standard
// error of that mean: a line's recent captures, where a drift persists and
// a capture's noise does not. Not read when none is.
RowDrift MeanRowDrift(std::span<const RowDrift> drifts);

// Whether a module's rows read off enough to warn of: beyond the offset the
// line index keeps a component within (max_row_offset_px, 0.1 px) and
// beyond 4 of the reading's standard errors. A calibrated module's reading
// scatters with its standard error (0.017-0.034 px on the demo's five
// scenes, 0.013-0.054 at speckle 0.4) about a small offset of its
// calibration's (about -0.02 px for the demo rig's module 1 over 15
// scenes): a capture of noise alone passes 0.1 px and 4 standard errors
// less than once in 1 000 (3.2 sigma at 0.025 px). Turned by 0.1 px, the
// demo's modules read 0.086-0.144 px, by 0.15 px 0.138 (the cup).
bool RowDriftWarned(const RowDrift& drift, double max_row_offset_px);

}  // namespace stereorig
