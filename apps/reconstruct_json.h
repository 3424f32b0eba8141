// The reconstruction report as JSON (shared by `reconstruct` and `bench`).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "reconstruct/runtime.h"
#include "reconstruct/score.h"

namespace stereorig {

// Per-step times (ms), point counts and fill rate per module, the merged
// totals and the shape fit. Keys carry their units.
nlohmann::json ReconstructionJson(const Reconstruction& rec);

// Accuracy figures against truth (score.h): points, mean_abs_mm, mean_mm,
// std_mm, rms_mm, p95_abs_mm, max_abs_mm, within_0_5_mm.
// With no point the figures are null, not 0 (which reads as a perfect score).
nlohmann::json ErrorFiguresJson(const ErrorFigures& f);

// "|e| 0.0345 std 0.0443" (mm) then `unit`, or "no point" when there is
// none to score; of the figures, or of ErrorFiguresJson's object of them.
std::string ErrorText(const ErrorFigures& f, const char* unit = "");
std::string ErrorText(const nlohmann::json& figures, const char* unit = "");

// The hole-filling points' figures (ErrorFiguresJson) and, under
// by_distance_to_measured, the same per band of distance to the nearest
// measured point (from_measured_mm: [from, to], null = no upper end).
nlohmann::json FilledJson(const CloudScore& score);

}  // namespace stereorig
