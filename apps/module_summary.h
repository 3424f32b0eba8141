// Console lines about where fill goes, read by a person: the losses by
// PixelStatus (`stereorig score` over the truth target, `stereorig
// reconstruct` over the grid-lit pixels) and `reconstruct`'s per-module
// summary (the report's searched_disparity_px and lit_pixels_by_status).
#pragma once

#include <span>
#include <string>

#include "reconstruct/runtime.h"

namespace stereorig {

// "no_sgm_match 4.1%, low_zncc 2.0%, ...": the pixels each status other than
// kPoint holds (counts indexed by the PixelStatus value), largest first, as
// shares of total_px. With max_reasons > 0 only that many, then ", ..." if
// there were more; "" when no pixel was lost.
std::string LossLine(std::span<const int> counts_by_status, int total_px, int max_reasons = 0);

// How ModuleSummary's first line words the fill.
struct FillWording {
  // The options are passive (IsPassive): the pixels the fill counts are lit
  // by ambient light, no grid: "lit px", not "grid-lit px".
  bool passive = false;
  // The run's first module line: say that the fill is the runtime's own
  // estimate (over the pixels it finds lit, no truth needed), which is not
  // `stereorig score`'s (over the truth's object pixels both cameras see):
  // on the demo cup 76.5 % against 94.1 % for the same module.
  bool say_whose = false;
};

// Two lines, no trailing newline, e.g.
//   module 1: 0 points, fill 0.0% of 36293 grid-lit px, match 82.7 ms
//     searched d [-21, 43) of [-100, 173) px; lit px without a point: no_sgm_match 29.8%, off_plane_coarse 18.7%, ...
// The reasons are LossLine's `max_reasons` largest over the lit pixels;
// "none" when every lit pixel has a point. A module with no point gets one
// more line, after the free-space test's: the status most of its lit
// pixels ended with and what to do about it (the measurement volume,
// object_size_mm, the passive options, the rig file, ...); with no lit
// pixel in the volume's ROI, whether the left image is lit elsewhere (the
// volume is beside the object: where to set it) or nowhere (no lit pixels:
// the projector off, a passive capture, a dark or flat image), from
// ModuleReport::camera_lit_pixels; a right image lit nowhere while the left
// is lit (ModuleReport::right_camera_lit_pixels) is named before any of
// those: that camera not triggered, not the volume.
std::string ModuleSummary(const ModuleReport& m, FillWording wording = {}, int max_reasons = 3);

// Why a module gave no point and what to do, "" for one with a point:
// ModuleSummary's last line without its "no point: " (the status most of its
// lit pixels ended with and its advice, or, with no lit pixel in the ROI,
// whether the left image is lit elsewhere or nowhere; a dark right image
// first). A batch's and a
// stream's warning line and a single capture's stderr give it too: a module
// that gives no point (lasers off, a camera not triggered, its cables
// swapped) must not pass as a measurement. `passive`: the run's options are
// passive (IsPassive): the advice does not ask for them.
std::string NoPointReason(const ModuleReport& m, bool passive);

// The ends of the volume's disparity range a module with points is warned
// of (ModuleReport::RangeEndsReached): "both ends", "the near end", "the far
// end", or "" (none reached, or no point). ModuleSummary's warning line and
// a batch's per-module line both name them so.
std::string RangeEndsWarnedOf(const ModuleReport& m);

// What to do where the object is not in the measurement volume: the
// no-point reasons and the range-end warnings end with it.
inline constexpr const char* kSetTheVolume =
    "set working_distance_mm (or volume_center_mm, volume_size_mm) to where it is (docs/reconstruct.md, \"When the "
    "fill rate is low\")";

// What a module whose rows read off (RowDrift::warned) means and what to do:
// ModuleSummary's warning line and a batch's per-module line end with it.
inline constexpr const char* kRowDriftAdvice =
    "a well calibrated module reads within about +-0.05 px; a camera turned or shifted since calibration reads more "
    "(0.011 deg is 0.2 px of rows at f ~1000 px), and from ~0.15-0.2 px the line index puts whole surfaces one grid "
    "period (~3.5 mm at 200 mm) off, often with the fill still high, or drops most of the module. Treat this "
    "module's points as suspect until the rig is checked: capture the calibration board as for a nightly check (8 or "
    "more views) and run `stereorig check --rig RIG --captures DIR --target BOARD`, recalibrating if it says so; "
    "`stereorig verify` on a reference artifact shows whether points are off (docs/reconstruct.md, \"Row drift\")";

}  // namespace stereorig
