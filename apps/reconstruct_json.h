// The reconstruction report as JSON (shared by `reconstruct` and `bench`).
#pragma once

#include <nlohmann/json.hpp>

#include "reconstruct/runtime.h"

namespace stereorig {

// Per-step times (ms), point counts and fill rate per module, the merged
// totals and the shape fit. Keys carry their units.
nlohmann::json ReconstructionJson(const Reconstruction& rec);

}  // namespace stereorig
