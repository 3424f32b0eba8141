#include "reconstruct/grid_period.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/grid_line_width.h"

namespace stereorig {
namespace {

// The longest lag summed, px: the later peaks of a short period (the m-th
// at m P) and the first of the longest period the options allow.
constexpr int kMaxLagPx = 128;

// A block's sums: s[k] the products g(x) g(x + k) of its detrended runs,
// n[k] how many pairs went into s[k].
struct LagSums {
  std::vector<double> s, n;
  explicit LagSums(int lags) : s(lags + 1, 0.0), n(lags + 1, 0.0) {}
};

// The run [x0, x1) of `row` as its central differences
// g(x) = (row(x + 1) - row(x - 1)) / 2 over its inner pixels x0 + 1 ..
// x1 - 2, mean removed: the lines' edges, with what varies slowly along the
// row (shading, albedo, and the near-horizontal family, whose lines cross a
// row at a few degrees as bumps tens of px wide) suppressed; their broad
// correlation would tilt the peaks at the period.
void Differences(const uint8_t* row, int x0, int x1, std::vector<double>* g) {
  const int length = x1 - x0 - 2;
  g->resize(length);
  double mean = 0;
  for (int i = 0; i < length; ++i) mean += (*g)[i] = 0.5 * (double(row[x0 + i + 2]) - row[x0 + i]);
  mean /= length;
  for (double& v : *g) v -= mean;
}

// Adds the run [x0, x1) of `row` to the autocorrelation sums, as its
// differences, at lags up to half its length (beyond, a peak rests on too
// few pairs).
void AddRun(const uint8_t* row, int x0, int x1, std::vector<double>* g, LagSums* sums) {
  Differences(row, x0, x1, g);
  const int length = int(g->size());
  const int lags = std::min<int>(length / 2, int(sums->s.size()) - 1);
  for (int k = 0; k <= lags; ++k) {
    double s = 0;
    for (int i = 0; i + k < length; ++i) s += (*g)[i] * (*g)[i + k];
    sums->s[k] += s, sums->n[k] += length - k;
  }
}

// Adds the cross-correlation of rows `a` and `b` (rows apart) over the
// columns [x0, x1) lit in both, at shifts -reach..reach of b against a,
// to c (index shift + reach): where the near-vertical lines of row a are
// found again in row b.
void AddRowPair(const uint8_t* a, const uint8_t* b, int x0, int x1, int reach, std::vector<double>* ga,
                std::vector<double>* gb, std::vector<double>* c) {
  Differences(a, x0, x1, ga);
  Differences(b, x0, x1, gb);
  const int length = int(ga->size());
  for (int s = -reach; s <= reach; ++s) {
    double sum = 0;
    for (int i = std::max(0, -s); i < length && i + s < length; ++i) sum += (*ga)[i] * (*gb)[i + s];
    (*c)[s + reach] += sum;
  }
}

// The normalised autocorrelation r[k] of a block's sums (r[0] = 1); NaN
// at lags no pair reached.
std::vector<double> Normalised(const LagSums& sums) {
  std::vector<double> r(sums.s.size(), std::nan(""));
  if (!(sums.n[0] > 0 && sums.s[0] > 0)) return r;
  const double variance = sums.s[0] / sums.n[0];
  for (size_t k = 0; k < r.size(); ++k)
    if (sums.n[k] > 0) r[k] = sums.s[k] / sums.n[k] / variance;
  return r;
}

// The peak's position between the lags k - 1, k, k + 1 (k's neighbours
// both lower or equal): the vertex of the parabola through the logarithms
// of the three values, exact for a Gaussian peak (a train of lines with
// Gaussian-like profiles correlates into Gaussian-like peaks; the parabola
// through the values themselves pulls the position towards k, by ~0.01 px
// at the simulator's line width); through the values where one is <= 0.
// Within half a lag of k.
double PeakPosition(const std::vector<double>& r, int k) {
  double a = r[k - 1], b = r[k], c = r[k + 1];
  if (a > 0 && b > 0 && c > 0) a = std::log(a), b = std::log(b), c = std::log(c);
  const double curvature = a - 2 * b + c;
  if (!(curvature < 0)) return k;
  return k + std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
}

bool IsPeak(const std::vector<double>& r, int k) {
  return k + 1 < int(r.size()) && !std::isnan(r[k + 1]) && r[k] >= r[k - 1] && r[k] > r[k + 1];
}

// The period of one block from its autocorrelation, or NaN.
double BlockPeriodPx(const std::vector<double>& r, const GridPeriodOptions& o) {
  // The first peak: the first local maximum that is high enough and stands
  // above a dip (the dark between two lines) at a smaller lag.
  double lowest = 1, first = std::nan("");
  for (int k = 1; k <= o.max_period_px && k + 1 < int(r.size()) && !std::isnan(r[k]); ++k) {
    lowest = std::min(lowest, r[k]);
    if (k >= 2 && IsPeak(r, k) && r[k] >= o.min_peak && r[k] - lowest >= o.min_peak_dip) {
      first = PeakPosition(r, k);
      break;
    }
  }
  if (std::isnan(first)) return first;
  // The later peaks near m P, while they stay clear: P fitted through the
  // origin to their positions, sum(m x_m) / sum(m^2).
  double sum_mx = first, sum_mm = 1, period = first;
  for (int m = 2;; ++m) {
    const int reach = std::max(1, int(period / 3));
    const int expected = int(std::lround(m * period));
    const int lo = expected - reach, hi = expected + reach;
    if (hi + 1 >= int(r.size()) || std::isnan(r[hi + 1])) break;
    int best = lo;
    for (int k = lo; k <= hi; ++k)
      if (r[k] > r[best]) best = k;
    if (best == lo || best == hi || !IsPeak(r, best) || r[best] < o.min_peak) break;
    sum_mx += m * PeakPosition(r, best), sum_mm += double(m) * m;
    period = sum_mx / sum_mm;
  }
  return period;
}

// The q-quantile of sorted values, linearly interpolated.
double Quantile(const std::vector<double>& sorted, double q) {
  const double at = q * (sorted.size() - 1);
  const size_t i = size_t(at);
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (at - i) * (sorted[i + 1] - sorted[i]);
}

// The lit runs of each row: lit pixels joined across gaps up to
// max_period_px (the dark centres of a long period's cells), those at
// least min_run_px long, as [begin, end) columns.
std::vector<std::vector<std::pair<int, int>>> LitRuns(const cv::Mat& lit, const GridPeriodOptions& o) {
  std::vector<std::vector<std::pair<int, int>>> runs(lit.rows);
  for (int y = 0; y < lit.rows; ++y) {
    const uint8_t* on = lit.ptr<uint8_t>(y);
    for (int x = 0; x < lit.cols;) {
      if (!on[x]) {
        ++x;
        continue;
      }
      int end = x + 1, gap = 0;
      for (int xx = x + 1; xx < lit.cols && gap <= o.max_period_px; ++xx) {
        if (on[xx])
          end = xx + 1, gap = 0;
        else
          ++gap;
      }
      if (end - x >= o.min_run_px) runs[y].push_back({x, end});
      x = end;
    }
  }
  return runs;
}

// How far the near-vertical lines move along the row per row, px, in the
// block of rows [y0, y1) whose period is period_px. The cross-correlation
// of each row with the row r below (within the image), over the columns lit
// in both, summed over the block, peaks at r times that shift, looked for
// within half a period less a pixel (the peak one period over is the next
// line). Its three-point position is biased by a share of a pixel that
// depends on where the peak falls between two lags, so it is read at r = 4,
// 8, .., 32 (the peaks fall at different fractions; the separations stop
// where the shift fitted so far would put the peak past the reach) and the
// shift fitted through the origin, sum(r x_r) / sum(r^2). NaN where the
// first peak is missing.
double BlockShiftPerRowPx(const cv::Mat& left, const std::vector<std::vector<std::pair<int, int>>>& runs, int y0,
                          int y1, double period_px, const GridPeriodOptions& o) {
  const int reach = std::max(1, int(period_px / 2));
  std::vector<double> c, ga, gb;
  double sum_rx = 0, sum_rr = 0;
  for (int rows_apart = 4; rows_apart <= 32; rows_apart += 4) {
    if (sum_rr > 0 && rows_apart * std::abs(sum_rx / sum_rr) > reach - 1) break;
    c.assign(2 * reach + 1, 0.0);
    bool any = false;
    for (int y = y0; y < y1 && y + rows_apart < left.rows; ++y)
      for (const auto& [a0, a1] : runs[y])
        for (const auto& [b0, b1] : runs[y + rows_apart]) {
          const int x0 = std::max(a0, b0), x1 = std::min(a1, b1);
          if (x1 - x0 < o.min_run_px) continue;
          AddRowPair(left.ptr<uint8_t>(y), left.ptr<uint8_t>(y + rows_apart), x0, x1, reach, &ga, &gb, &c);
          any = true;
        }
    if (!any) break;
    int best = 1;
    for (int k = 1; k + 1 < int(c.size()); ++k)
      if (c[k] > c[best]) best = k;
    if (!(c[best] > 0) || !IsPeak(c, best)) break;
    sum_rx += rows_apart * (PeakPosition(c, best) - reach), sum_rr += double(rows_apart) * rows_apart;
  }
  return sum_rr > 0 ? sum_rx / sum_rr : std::nan("");
}

}  // namespace

double GridTurnDeg(const GridPeriodMeasurement& m) { return std::atan(std::abs(m.shift_per_row_px)) * 180 / M_PI; }

double RowOffsetPerPeriodPx(const GridPeriodMeasurement& m) { return m.period_px * std::abs(m.shift_per_row_px); }

std::optional<GridPeriodMeasurement> MeasureGridPeriodPx(const cv::Mat& left, const cv::Mat& lit,
                                                         const GridPeriodOptions& o) {
  STEREORIG_CHECK(left.type() == CV_8UC1 && lit.type() == CV_8UC1 && lit.size() == left.size());
  STEREORIG_CHECK(o.block_rows >= 1 && o.min_run_px >= 8 && o.max_period_px >= 3 && o.min_blocks >= 1);
  const int lags = std::min(kMaxLagPx, std::max(o.max_period_px + 2, left.cols / 2));
  const std::vector<std::vector<std::pair<int, int>>> runs = LitRuns(lit, o);
  GridPeriodMeasurement out;
  std::vector<double> periods, shifts, g;
  GridHarmonicPowers harmonics;
  for (int y0 = 0; y0 < left.rows; y0 += o.block_rows) {
    const int y1 = std::min(left.rows, y0 + o.block_rows);
    LagSums sums(lags);
    for (int y = y0; y < y1; ++y) {
      for (const auto& [x0, x1] : runs[y]) AddRun(left.ptr<uint8_t>(y), x0, x1, &g, &sums);
      out.rows += !runs[y].empty();
    }
    const double period = BlockPeriodPx(Normalised(sums), o);
    if (std::isnan(period)) continue;
    periods.push_back(period);
    if (period >= kMinLineWidthPeriodPx)
      for (int y = y0; y < y1; ++y)
        for (const auto& [x0, x1] : runs[y]) AddRunHarmonics(left.ptr<uint8_t>(y), x0, x1, period, &harmonics);
    const double shift = BlockShiftPerRowPx(left, runs, y0, y1, period, o);
    if (!std::isnan(shift)) shifts.push_back(shift);
  }
  if (int(periods.size()) < o.min_blocks) return std::nullopt;
  std::sort(periods.begin(), periods.end());
  out.blocks = int(periods.size());
  out.period_px = Quantile(periods, 0.5);
  out.spread_px = 0.5 * (Quantile(periods, 0.75) - Quantile(periods, 0.25));
  if (out.period_px >= kMinLineWidthPeriodPx)
    out.line_sigma_over_period = LineSigmaOverPeriod(harmonics, out.period_px);
  if (int(shifts.size()) >= o.min_blocks) {
    std::sort(shifts.begin(), shifts.end());
    out.shift_per_row_px = Quantile(shifts, 0.5);
  }
  return out;
}

}  // namespace stereorig
