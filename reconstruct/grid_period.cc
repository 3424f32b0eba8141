#include "reconstruct/grid_period.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "calib/core/input_error.h"

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

// Adds the run [x0, x1) of `row` to the sums, as its central differences
// g(x) = (row(x + 1) - row(x - 1)) / 2: the lines' edges, with what varies
// slowly along the row (shading, albedo, and the near-horizontal family,
// whose lines cross a row at a few degrees as bumps tens of px wide)
// suppressed; their broad correlation would tilt the peaks at the period.
// Lags up to half the run's length (beyond, a peak rests on too few pairs).
void AddRun(const uint8_t* row, int x0, int x1, std::vector<double>* g, LagSums* sums) {
  const int length = x1 - x0 - 2;  // the differences of the run's inner pixels
  g->resize(length);
  double mean = 0;
  for (int i = 0; i < length; ++i) mean += (*g)[i] = 0.5 * (double(row[x0 + i + 2]) - row[x0 + i]);
  mean /= length;
  for (double& v : *g) v -= mean;
  const int lags = std::min<int>(length / 2, int(sums->s.size()) - 1);
  for (int k = 0; k <= lags; ++k) {
    double s = 0;
    for (int i = 0; i + k < length; ++i) s += (*g)[i] * (*g)[i + k];
    sums->s[k] += s, sums->n[k] += length - k;
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

}  // namespace

std::optional<GridPeriodMeasurement> MeasureGridPeriodPx(const cv::Mat& left, const cv::Mat& lit,
                                                         const GridPeriodOptions& o) {
  STEREORIG_CHECK(left.type() == CV_8UC1 && lit.type() == CV_8UC1 && lit.size() == left.size());
  STEREORIG_CHECK(o.block_rows >= 1 && o.min_run_px >= 8 && o.max_period_px >= 3);
  const int lags = std::min(kMaxLagPx, std::max(o.max_period_px + 2, left.cols / 2));
  GridPeriodMeasurement out;
  std::vector<double> periods, g;
  for (int y0 = 0; y0 < left.rows; y0 += o.block_rows) {
    LagSums sums(lags);
    for (int y = y0; y < std::min(left.rows, y0 + o.block_rows); ++y) {
      const uint8_t* row = left.ptr<uint8_t>(y);
      const uint8_t* on = lit.ptr<uint8_t>(y);
      bool row_used = false;
      for (int x = 0; x < left.cols;) {
        if (!on[x]) {
          ++x;
          continue;
        }
        // A run: lit pixels joined across gaps up to max_period_px.
        int end = x + 1, gap = 0;
        for (int xx = x + 1; xx < left.cols && gap <= o.max_period_px; ++xx) {
          if (on[xx])
            end = xx + 1, gap = 0;
          else
            ++gap;
        }
        if (end - x >= o.min_run_px) AddRun(row, x, end, &g, &sums), row_used = true;
        x = end;
      }
      out.rows += row_used;
    }
    const double period = BlockPeriodPx(Normalised(sums), o);
    if (!std::isnan(period)) periods.push_back(period);
  }
  if (int(periods.size()) < o.min_blocks) return std::nullopt;
  std::sort(periods.begin(), periods.end());
  out.blocks = int(periods.size());
  out.period_px = Quantile(periods, 0.5);
  out.spread_px = 0.5 * (Quantile(periods, 0.75) - Quantile(periods, 0.25));
  return out;
}

}  // namespace stereorig
