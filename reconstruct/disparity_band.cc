#include "reconstruct/disparity_band.h"

#include <algorithm>
#include <cmath>

namespace stereorig {

std::optional<DisparityBand> OccupiedDisparityBand(const std::vector<float>& disparities_px, int margin_px) {
  const int n = int(disparities_px.size());
  if (n < kMinBandMatches) return std::nullopt;
  const auto [lo_it, hi_it] = std::minmax_element(disparities_px.begin(), disparities_px.end());
  const double origin = std::floor(*lo_it);
  const int bins = int((*hi_it - origin) / kBandBinPx) + 1;
  std::vector<int> count(bins, 0);
  for (float d : disparities_px) ++count[int((d - origin) / kBandBinPx)];

  const int sparse = std::max(2, int(std::ceil(kSparseShare * n)));
  const int max_gap_bins = int(kMaxGapPx / kBandBinPx);
  int kept_lo = -1, kept_hi = -1;  // bins
  for (int b = 0; b < bins;) {
    if (count[b] < sparse) {
      ++b;
      continue;
    }
    // A cluster: from bin b, bridging up to max_gap_bins sparse bins.
    int first = b, last = b, weight = 0;
    for (int gap = 0; b < bins && gap <= max_gap_bins; ++b) {
      if (count[b] < sparse) {
        ++gap;
        continue;
      }
      weight += count[b];
      last = b;
      gap = 0;
    }
    b = last + 1;
    if (weight < kMinClusterShare * n) continue;
    if (kept_lo < 0) kept_lo = first;
    kept_hi = last;
  }
  if (kept_lo < 0) return std::nullopt;  // only small scattered clusters: no trustworthy band
  DisparityBand band;
  band.min_px = int(std::floor(origin + kept_lo * kBandBinPx)) - margin_px;
  band.max_px = int(std::ceil(origin + (kept_hi + 1) * kBandBinPx)) + margin_px;
  return band;
}

RangeEnds RangeEndsReached(int min_disparity_px, int num_disparities, int occupied_min_px, int occupied_end_px) {
  if (occupied_end_px <= occupied_min_px || num_disparities <= 0) return {};
  return {.near = min_disparity_px + num_disparities - occupied_end_px <= kBandBinPx,
          .far = occupied_min_px - min_disparity_px <= kBandBinPx};
}

RangeEnds RangeEndsHeld(const std::vector<float>& disparities_px, int min_disparity_px, int num_disparities) {
  const int end_px = min_disparity_px + num_disparities;
  int at_near = 0, at_far = 0;
  for (float d : disparities_px) {
    at_near += d >= end_px - kBandBinPx;
    at_far += d < min_disparity_px + kBandBinPx;
  }
  const int enough = std::max(2, int(std::ceil(kSparseShare * disparities_px.size())));
  return {.near = at_near >= enough, .far = at_far >= enough};
}

}  // namespace stereorig
