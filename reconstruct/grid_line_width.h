// How wide the laser grid's lines are for their period, measured from a
// rectified left image: sigma / P, the Gaussian line profile's standard
// deviation over the period, along the rows.
//
// The runtime's tests were tuned and scored on the simulator's default
// grid, whose lines are narrow for their period (sigma / P ~0.13). Where
// the lines fill more of the period, the grid's contrast fades into a
// near-sinusoid: a window shifted by one period looks the same, and the
// census and the line index's vernier lose what tells one line from the
// next (docs/reconstruct.md, "Another projector").
//
// Along a row, a train of Gaussian lines sigma wide and P apart has the
// Fourier amplitudes a_k ~ exp(-2 pi^2 k^2 sigma^2 / P^2) at the harmonics
// k / P, each times the pixel's box, sinc(k / P). So the first two give
// sigma / P = sqrt(ln((a_1 / sinc(1 / P)) / (a_2 / sinc(2 / P))) / (6 pi^2)).
// The powers at 1 / P and 2 / P are summed over each lit run (mean
// removed, Hann-windowed), and the power at 2.5 / P, between the harmonics,
// is taken off both as the noise floor (sensor noise and speckle are
// broadband; the other line family crosses a row as bumps tens of px wide,
// far below 1 / P). A grid turned by theta stretches both the period and
// the width along the row by 1 / cos(theta): their ratio is the grid's own.
#pragma once

#include <cstdint>

namespace stereorig {

// The shortest period whose second harmonic and noise probe (2.5 / P) stay
// below the rows' Nyquist frequency, 0.5 / px.
inline constexpr double kMinLineWidthPeriodPx = 5;

// Pixels at this grey level are left out, with half a period either side:
// a clipped peak is flat-topped, so its harmonics read as a wider line (a
// crossing of two lines saturates first). The stretches of a run between
// them count if they are kMinPeriodsPerStretch periods long.
inline constexpr int kSaturatedDn = 255;
inline constexpr double kMinPeriodsPerStretch = 4;

// Powers summed over stretches of runs: at 1 / P, 2 / P and 2.5 / P (the
// floor).
struct GridHarmonicPowers {
  double first = 0, second = 0, floor = 0;
  int stretches = 0;
};

// Adds the run [x0, x1) of `row` (grey levels) to *sums at the period
// period_px along the row (>= kMinLineWidthPeriodPx): its stretches clear
// of saturated pixels.
void AddRunHarmonics(const uint8_t* row, int x0, int x1, double period_px, GridHarmonicPowers* sums);

// sigma / P from the summed powers at the period period_px, or NaN where
// the second harmonic does not stand above the floor (lines so wide that
// the profile is a sinusoid within the noise, or no grid).
double LineSigmaOverPeriod(const GridHarmonicPowers& sums, double period_px);

}  // namespace stereorig
