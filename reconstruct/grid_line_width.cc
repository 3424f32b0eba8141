#include "reconstruct/grid_line_width.h"

#include <cmath>
#include <complex>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

// The pixel box's attenuation at the frequency f, cycles per px.
double Sinc(double f) { return f == 0 ? 1 : std::sin(M_PI * f) / (M_PI * f); }

// The powers of row[x0, x1) at 1 / P, 2 / P and 2.5 / P, mean removed and
// Hann-windowed, added to *sums.
void AddStretch(const uint8_t* row, int x0, int x1, double period_px, GridHarmonicPowers* sums) {
  const int n = x1 - x0;
  double mean = 0;
  for (int x = x0; x < x1; ++x) mean += row[x];
  mean /= n;
  const double frequencies[3] = {1 / period_px, 2 / period_px, 2.5 / period_px};
  std::complex<double> s[3];
  for (int i = 0; i < n; ++i) {
    const double hann = 0.5 - 0.5 * std::cos(2 * M_PI * (i + 0.5) / n);
    const double v = hann * (row[x0 + i] - mean);
    for (int k = 0; k < 3; ++k) s[k] += v * std::polar(1.0, -2 * M_PI * frequencies[k] * i);
  }
  sums->first += std::norm(s[0]);
  sums->second += std::norm(s[1]);
  sums->floor += std::norm(s[2]);
  ++sums->stretches;
}

}  // namespace

void AddRunHarmonics(const uint8_t* row, int x0, int x1, double period_px, GridHarmonicPowers* sums) {
  STEREORIG_CHECK(period_px >= kMinLineWidthPeriodPx);
  // Each stretch of the run at least half a period clear of a saturated
  // pixel on both sides (so the clipped line is out of it) and
  // kMinPeriodsPerStretch periods long.
  const int margin = int(std::ceil(period_px / 2));
  const int shortest = int(std::ceil(kMinPeriodsPerStretch * period_px));
  int begin = x0;
  for (int x = x0; x <= x1; ++x) {
    if (x < x1 && row[x] < kSaturatedDn) continue;
    const int end = x < x1 ? x - margin : x1;
    if (end - begin >= shortest) AddStretch(row, begin, end, period_px, sums);
    begin = x + 1 + margin;
  }
}

double LineSigmaOverPeriod(const GridHarmonicPowers& sums, double period_px) {
  const double first = sums.first - sums.floor, second = sums.second - sums.floor;
  if (!(sums.stretches > 0 && first > 0 && second > 0 && first > second)) return std::nan("");
  const double amplitude_ratio = std::sqrt(first / second) * Sinc(2 / period_px) / Sinc(1 / period_px);
  if (!(amplitude_ratio > 1)) return std::nan("");
  return std::sqrt(std::log(amplitude_ratio) / (6 * M_PI * M_PI));
}

}  // namespace stereorig
