// A module's row drift: how far its rectified rows are off, read from the
// laser grid's vernier (line_index.h) at no extra cost.
//
// The line index tells the grid's lines apart by a row offset of ~0.36 px
// per period (8 px x tan 2.6 deg) and keeps a component that reads within
// max_row_offset_px (0.1 px) of 0. That is a tolerance on the calibration
// too: a camera turned by 0.011 deg since calibration (0.2 px of rows at
// f = 1025 px) makes every correct match read 0.2 px, past half a period's
// step, and the line index then puts whole surfaces one period off (~3.5 mm
// at 200 mm) with no fill lost. Measured on the demo's cup, module 0's right
// camera turned about its x axis: mean |error| 0.035 mm at 0.1 px, 0.037 mm at
// 0.15 px, 2.17 mm at 0.2 px and 2.15 mm at 0.5 px (docs/reconstruct-log.md,
// "Session 47"). So the readings are worth reporting on every capture: the
// components the line index kept or moved read the module's row offset (or
// that offset less a whole number of steps: the vernier cannot tell a drift
// of s from one of s - 0.36 px, so a drift near a whole step reads ~0).
#pragma once

#include <span>

#include "reconstruct/line_index.h"

namespace stereorig {

struct RowDrift {
  bool read = false;               // some component gave a reading
  double row_offset_px = 0;        // the pixel-weighted median reading
  double standard_error_px = 0;    // that reading's own standard error
  int components = 0, pixels = 0;  // the readings it is over
  bool warned = false;             // RowDriftWarned, as the runtime's options set it
};

// The pixel-weighted median of the components' readings (the reading
// covering the middle pixel when they are sorted by offset): one large
// surface decides, a few small wrong components do not.
RowDrift ReadRowDrift(std::span<const VernierReading> readings);

// Whether a module's rows read off enough to warn of: beyond 3/4 of the
// offset the line index keeps a component within (max_row_offset_px) and
// beyond 3 of the reading's standard errors. On the demo's five scenes with
// the calibrated rig every module reads within 0.046 px (standard errors
// 0.017-0.034); turned by 0.1 px every turned module reads 0.086-0.144 px.
bool RowDriftWarned(const RowDrift& drift, double max_row_offset_px);

}  // namespace stereorig
