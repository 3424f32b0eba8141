#include "apps/module_summary.h"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <vector>

namespace stereorig {

std::string LossLine(std::span<const int> counts_by_status, int total_px, int max_reasons) {
  std::vector<std::pair<int, size_t>> losses;  // (count, status)
  for (size_t k = 0; k < counts_by_status.size(); ++k)
    if (counts_by_status[k] && k != size_t(PixelStatus::kPoint)) losses.push_back({counts_by_status[k], k});
  std::sort(losses.rbegin(), losses.rend());
  const size_t shown = max_reasons > 0 ? std::min(losses.size(), size_t(max_reasons)) : losses.size();
  std::string line;
  char buf[64];
  for (size_t i = 0; i < shown; ++i) {
    std::snprintf(buf, sizeof buf, "%s%s %.1f%%", i ? ", " : "", PixelStatusName(PixelStatus(losses[i].second)),
                  100.0 * losses[i].first / std::max(1, total_px));
    line += buf;
  }
  if (shown < losses.size()) line += ", ...";
  return line;
}

namespace {

constexpr const char* kSetTheVolume =
    "set working_distance_mm (or volume_center_mm, volume_size_mm) to where it is (docs/reconstruct.md, \"When the "
    "fill rate is low\")";

// The line a module with no point gets, "" for one with a point. With lit
// pixels and none kept, most often the object is not in the measurement
// volume (a rig used at another distance than the defaults' 200 mm finds
// nothing, and exit 0 alone would not say why). With none lit where the
// volume projects (lit_pixels counts only its ROI), the left image is lit
// elsewhere (the volume is beside the object) or nowhere (a dark or flat
// image): camera_lit_pixels tells which (-1: not counted).
std::string NoPointHint(const ModuleReport& m) {
  if (m.points > 0) return "";
  if (m.lit_pixels > 0)
    return std::string("\n  no point: if the object is not in the measurement volume, ") + kSetTheVolume;
  if (m.camera_lit_pixels > 0)
    return "\n  no point: " + std::to_string(m.camera_lit_pixels) +
           " px of the left camera's image are grid-lit, none where the measurement volume projects: the volume is "
           "beside the object; " +
           kSetTheVolume;
  if (m.camera_lit_pixels == 0)
    return "\n  no point: no pixel of the left camera's image is grid-lit (9x9 std above lit_contrast_dn): a dark or "
           "flat image (the grid off or out of view, too short an exposure); check the capture";
  return std::string(
             "\n  no point: no grid-lit pixel where the measurement volume projects: if the object is not in "
             "the volume, ") +
         kSetTheVolume;
}

// A module whose matches reach an end of the volume's disparity range
// (ModuleReport::RangeEndsReached): its points may be a copy of the grid
// whole periods off, where nothing is. "" otherwise, or with no point.
std::string RangeEndWarning(const ModuleReport& m) {
  const std::string which = RangeEndsWarnedOf(m);
  if (which.empty()) return "";
  return "\n  warning: its matches reach " + which + " of the measurement volume's disparity range (the band pass's " +
         "d [" + std::to_string(m.occupied_min_disparity_px) + ", " + std::to_string(m.occupied_end_disparity_px) +
         ") of [" + std::to_string(m.min_disparity_px) + ", " + std::to_string(m.min_disparity_px + m.num_disparities) +
         ") px): the object may go on past the volume, or the laser grid was matched whole periods off (it repeats "
         "along the rows), its points where nothing is; if the object is not well inside the volume, " +
         kSetTheVolume;
}

}  // namespace

std::string RangeEndsWarnedOf(const ModuleReport& m) {
  const ModuleReport::RangeEnds ends = m.RangeEndsReached();
  if (m.points == 0 || !(ends.near || ends.far)) return "";
  return ends.near && ends.far ? "both ends" : ends.near ? "the near end" : "the far end";
}

std::string ModuleSummary(const ModuleReport& m, int max_reasons) {
  const auto match = m.times_ms.find("match");
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "module %d: %d points, fill %.1f%% of %d grid-lit px, match %.1f ms\n"
                "  searched d [%d, %d) of [%d, %d) px; lit px without a point: ",
                m.module, m.points, 100 * m.fill_rate(), m.lit_pixels, match == m.times_ms.end() ? 0.0 : match->second,
                m.searched_min_disparity_px, m.searched_min_disparity_px + m.searched_num_disparities,
                m.min_disparity_px, m.min_disparity_px + m.num_disparities);
  const std::string losses = LossLine(m.lit_by_status, m.lit_pixels, std::max(1, max_reasons));
  const std::string seen = m.seen_through > 0
                               ? "\n  " + std::to_string(m.seen_through) +
                                     " points removed, seen through (free_space_test; " +
                                     std::to_string(m.seen_through_surface) + " of them with their surface)"
                               : "";
  return buf + (losses.empty() ? "none" : losses) + seen + RangeEndWarning(m) + NoPointHint(m);
}

}  // namespace stereorig
