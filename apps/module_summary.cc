#include "apps/module_summary.h"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <vector>

#include "calib/core/capture_image_name.h"

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

constexpr const char* kPassiveOptions =
    "a capture without the laser grid (passive) needs crop_to_lit_region: false and match: {min_distinctness: 0, "
    "grid_line_test: false, line_index: false} (`stereorig demo` writes them, passive_options.yaml)";

// What the status most of a module's lit pixels ended with says of a module
// with no point, and what to do. Before, every such module was told to move
// the measurement volume, also when the volume was right and another test
// took every pixel (object_size, a passive capture's grid tests, a swapped
// module's images, which no search can match).
std::string AdviceFor(PixelStatus status, bool passive) {
  switch (status) {
    case PixelStatus::kOutsideVolume:
      return std::string("they were matched outside the measurement volume: if the object is not in it, ") +
             kSetTheVolume;
    case PixelStatus::kObjectSize:
      return "they lie farther than object_size_mm from the module's median point: set object_size_mm to at least "
             "the object's largest dimension";
    case PixelStatus::kLowConfidence:
      return "their matches' confidence is below min_confidence: lower it";
    case PixelStatus::kSeenThrough:
    case PixelStatus::kSeenThroughSurface:
      return "the free-space test found other modules' surfaces in front of them: check the modules' poses in the "
             "rig file (`stereorig check`), or set free_space_test: false to see what it removed";
    case PixelStatus::kWrongLine:
      // A module whose rows drifted past ~0.18 px loses most of its pixels
      // so (docs/reconstruct.md, "Row drift": 0.2 px of rows the other way
      // left the demo cup's module 0 at 1 % fill, 78 % wrong_line).
      return std::string(
                 "the line index could not tell which laser line they are on: the rig's rows may be off (a "
                 "camera turned since calibration: run `stereorig check`), or ") +
             kPassiveOptions + "; with the grid, its period may not be the options' (`stereorig tune`)";
    case PixelStatus::kNotDistinct:
    case PixelStatus::kNoGridLine:
      return std::string("the laser grid's own tests refused their matches: ") + kPassiveOptions +
             "; with the grid, its period may not be the options' (`stereorig tune`)";
    case PixelStatus::kNoSgmMatch:
    case PixelStatus::kNoPlane:
    case PixelStatus::kOffPlaneCoarse:
    case PixelStatus::kOutOfRange:
      // Passive options already: telling the user to set them sent them in
      // a circle (a passive plain plate, which no search matches).
      if (passive)
        return std::string(
                   "the search found no consistent match: without the laser grid (these options are passive) a "
                   "weakly textured surface (a plain plate, a glaze) gives few matches or none, which is what the "
                   "grid is for; or the object may not be in the measurement volume (") +
               kSetTheVolume +
               "), or the module's two images may not be a stereo pair of this rig (its cameras swapped or moved: "
               "check the rig file, `stereorig check`)";
      return std::string("the search found no consistent match: the object may not be in the measurement volume (") +
             kSetTheVolume +
             "), the module's two images may not be a stereo pair of this rig (its cameras swapped or moved: check "
             "the rig file, `stereorig check`), or " +
             kPassiveOptions;
    default:
      return "see docs/reconstruct.md, \"When the fill rate is low\", for what that test refuses";
  }
}

}  // namespace

// With lit pixels and none kept, the advice follows the status most of them
// ended with (AdviceFor). With none lit where the volume projects (lit_pixels
// counts only its ROI), the left image is lit elsewhere (the volume is
// beside the object) or nowhere (no grid: a dark or flat image, the
// projector off, or a passive capture): camera_lit_pixels tells which (-1:
// not counted). A right image grid-lit nowhere while the left is lit comes
// first: whatever status the left's pixels ended with, no search could match
// them, and the volume's advice would send the user the wrong way.
std::string NoPointReason(const ModuleReport& m, bool passive) {
  if (m.points > 0) return "";
  if (m.right_camera_lit_pixels == 0 && (m.lit_pixels > 0 || m.camera_lit_pixels > 0))
    return "no pixel of the right camera's image (" + CameraImageName(m.right_camera) +
           ") is grid-lit (9x9 std above lit_contrast_dn), while the left camera's (" + CameraImageName(m.left_camera) +
           ") is: a dark or flat right image (that camera not triggered, too short an exposure, the grid out of its "
           "view), which no search can match; check the capture";
  if (m.lit_pixels > 0) {
    size_t top = size_t(PixelStatus::kNotSearched);
    for (size_t k = 0; k < m.lit_by_status.size(); ++k)
      if (k != size_t(PixelStatus::kPoint) && m.lit_by_status[k] > m.lit_by_status[top]) top = k;
    char share[96];
    std::snprintf(share, sizeof share, "%s %.1f%% of the lit pixels: ", PixelStatusName(PixelStatus(top)),
                  100.0 * m.lit_by_status[top] / m.lit_pixels);
    return share + AdviceFor(PixelStatus(top), passive);
  }
  if (m.camera_lit_pixels > 0)
    return std::to_string(m.camera_lit_pixels) +
           " px of the left camera's image are grid-lit, none where the measurement volume projects: the volume is "
           "beside the object; " +
           kSetTheVolume;
  if (m.camera_lit_pixels == 0)
    return "no lit pixels: is the projector on, or is this a passive capture? No pixel of the left "
           "camera's image is grid-lit (9x9 std above lit_contrast_dn): a dark or flat image (the grid off or out of "
           "view, a camera not triggered, too short an exposure); check the capture";
  return std::string("no grid-lit pixel where the measurement volume projects: if the object is not in the volume, ") +
         kSetTheVolume;
}

namespace {

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

// A module whose rows read off at the grid's vernier (row_drift.h).
std::string RowDriftWarning(const ModuleReport& m) {
  if (!m.row_drift.warned) return "";
  char buf[160];
  std::snprintf(buf, sizeof buf, "%+.3f px (standard error %.3f, %d component%s)", m.row_drift.row_offset_px,
                m.row_drift.standard_error_px, m.row_drift.components, m.row_drift.components == 1 ? "" : "s");
  return std::string("\n  warning: its rectified rows read ") + buf +
         " off at the laser grid's vernier (row_drift): " + kRowDriftAdvice;
}

}  // namespace

std::string RangeEndsWarnedOf(const ModuleReport& m) {
  const ModuleReport::RangeEnds ends = m.RangeEndsReached();
  if (m.points == 0 || !(ends.near || ends.far)) return "";
  return ends.near && ends.far ? "both ends" : ends.near ? "the near end" : "the far end";
}

std::string ModuleSummary(const ModuleReport& m, FillWording wording, int max_reasons) {
  const auto match = m.times_ms.find("match");
  char buf[384];
  std::snprintf(
      buf, sizeof buf,
      "module %d: %d points, fill %.1f%% of %d %s px%s, match %.1f ms\n"
      "  searched d [%d, %d) of [%d, %d) px; lit px without a point: ",
      m.module, m.points, 100 * m.fill_rate(), m.lit_pixels, wording.passive ? "lit" : "grid-lit",
      wording.say_whose ? " (the runtime's own estimate; `stereorig score` measures fill against the truth)" : "",
      match == m.times_ms.end() ? 0.0 : match->second, m.searched_min_disparity_px,
      m.searched_min_disparity_px + m.searched_num_disparities, m.min_disparity_px,
      m.min_disparity_px + m.num_disparities);
  const std::string losses = LossLine(m.lit_by_status, m.lit_pixels, std::max(1, max_reasons));
  const std::string seen = m.seen_through > 0
                               ? "\n  " + std::to_string(m.seen_through) +
                                     " points removed, seen through (free_space_test; " +
                                     std::to_string(m.seen_through_surface) + " of them with their surface)"
                               : "";
  const std::string no_point = NoPointReason(m, wording.passive);
  return buf + (losses.empty() ? "none" : losses) + seen + RangeEndWarning(m) + RowDriftWarning(m) +
         (no_point.empty() ? "" : "\n  no point: " + no_point);
}

}  // namespace stereorig
