// The reconstruction report as JSON (shared by `reconstruct` and `bench`).
#pragma once

#include <nlohmann/json.hpp>

#include "reconstruct/runtime.h"
#include "reconstruct/score.h"

namespace stereorig {

// Per-step times (ms), point counts and fill rate per module, the merged
// totals and the shape fit. Keys carry their units.
nlohmann::json ReconstructionJson(const Reconstruction& rec);

// Accuracy figures against truth (score.h): points, mean_abs_mm, mean_mm,
// std_mm, rms_mm, p95_abs_mm, max_abs_mm, within_0_5_mm.
nlohmann::json ErrorFiguresJson(const ErrorFigures& f);

// The hole-filling points' figures (ErrorFiguresJson) and, under
// by_distance_to_measured, the same per band of distance to the nearest
// measured point (from_measured_mm: [from, to], null = no upper end).
nlohmann::json FilledJson(const CloudScore& score);

}  // namespace stereorig
