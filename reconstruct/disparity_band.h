// The band of disparities a scene occupies, from the matches of a cheap
// coarse pass: the full-resolution search then covers only that band instead
// of the whole measurement volume's range.
//
// The coarse pass (half-resolution SGM over the whole range) is right on the
// object but not everywhere: a laser grid looks alike shifted by whole
// periods, so 5-50 % of its matches are mismatches spread over the whole
// range (measured on the simulator's scenes: a 2nd-98th percentile band was
// 2-5x wider than the disparities the final cloud holds, up to the whole
// range on the ball bar). Two steps remove them: the caller first drops
// small blobs of the coarse map (kCoarseSpeckle*: mismatches come in small
// patches, surfaces in large ones); then clusters are formed here from runs
// of 4 px histogram bins holding matches, bridged across gaps up to
// kMaxGapPx, a cluster holding less than kMinClusterShare of the matches is
// dropped, and the band spans every kept cluster.
#pragma once

#include <optional>
#include <vector>

namespace stereorig {

struct DisparityBand {
  int min_px = 0;  // smallest disparity of the band, px
  int max_px = 0;  // largest, px (inclusive)
};

inline constexpr double kBandBinPx = 4;            // histogram bin width, px
inline constexpr double kMaxGapPx = 24;            // empty or sparse bins bridged within a cluster, px (3 grid periods)
inline constexpr double kMinClusterShare = 0.1;    // clusters with less of the matches are coarse mismatches
inline constexpr double kSparseShare = 0.001;      // a bin with less of the matches counts as empty
inline constexpr int kMinBandMatches = 200;        // fewer matches: no band (search the full range)
inline constexpr int kCoarseSpeckleWindowPx = 50;  // coarse blobs smaller than this are dropped, half-res px
inline constexpr double kCoarseSpeckleRangePx = 1.0;  // neighbours within this are one blob, half-res px

// disparities_px: the coarse pass's valid matches, in full-resolution px.
// Returns [lowest kept cluster - margin_px, highest + margin_px], or nothing
// if there are fewer than kMinBandMatches matches.
std::optional<DisparityBand> OccupiedDisparityBand(const std::vector<float>& disparities_px, int margin_px);

// Which ends of a searched range [min_disparity_px, min_disparity_px +
// num_disparities) the band's kept bins [occupied_min_px, occupied_end_px)
// (before their margin) reach, within one bin (kBandBinPx); near = the
// largest disparities. Neither when there is no band (end <= min). Reached,
// the surface may go on past the range, or the laser grid was matched whole
// periods off, a copy of itself inside the range: the range likely misses
// the object. `reconstruct` reports it per module (ModuleReport), `match`
// for its --min-disparity / --num-disparities.
struct RangeEnds {
  bool near = false, far = false;
};
RangeEnds RangeEndsReached(int min_disparity_px, int num_disparities, int occupied_min_px, int occupied_end_px);

// Which ends of the same range a map's final disparities reach: at least
// kSparseShare of them (and 2) within one bin (kBandBinPx) of the end. The
// band alone can reach an end the output does not: its half-resolution
// pass also matches the unlit background and the region's edges (on the
// demo cup's module 0, a cluster at -16..0 px, 99 % unlit, where every
// final disparity lay at 43-105 px), so `match` warns only of an end both
// reach.
RangeEnds RangeEndsHeld(const std::vector<float>& disparities_px, int min_disparity_px, int num_disparities);

}  // namespace stereorig
