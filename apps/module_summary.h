// The console lines `stereorig reconstruct` prints per module: points, fill,
// match time, then what was searched and where the lit pixels without a
// point went (the report's searched_disparity_px and lit_pixels_by_status,
// read by a person at the line).
#pragma once

#include <string>

#include "reconstruct/runtime.h"

namespace stereorig {

// Two lines, no trailing newline, e.g.
//   module 1: 0 points, fill 0.0% of 36293 grid-lit px, match 82.7 ms
//     searched d [-21, 43) of [-100, 173) px; lit px without a point: no_sgm_match 29.8%, off_plane_coarse 18.7%, ...
// The reasons are the `max_reasons` largest, largest first, as shares of the
// lit pixels; "none" when every lit pixel has a point.
std::string ModuleSummary(const ModuleReport& m, int max_reasons = 3);

}  // namespace stereorig
