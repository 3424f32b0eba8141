#include "apps/reconstruct_json.h"

#include <cmath>
#include <cstdio>

namespace stereorig {

nlohmann::json ReconstructionJson(const Reconstruction& rec) {
  nlohmann::json j;
  int lit = 0, filled = 0;
  for (const ModuleReport& m : rec.modules) {
    nlohmann::json mj = {{"module", m.module},
                         {"points", m.points},
                         {"points_seen_through", m.seen_through},
                         {"points_on_seen_through_surfaces", m.seen_through_surface},
                         {"lit_pixels", m.lit_pixels},
                         {"lit_pixels_filled", m.lit_filled},
                         {"fill_rate", m.fill_rate()},
                         {"match_roi_px", {m.match_roi.x, m.match_roi.y, m.match_roi.width, m.match_roi.height}},
                         {"disparity_range_px", {m.min_disparity_px, m.min_disparity_px + m.num_disparities}},
                         {"searched_disparity_px",
                          {m.searched_min_disparity_px, m.searched_min_disparity_px + m.searched_num_disparities}}};
    if (m.occupied_end_disparity_px > m.occupied_min_disparity_px)
      mj["occupied_disparity_px"] = {m.occupied_min_disparity_px, m.occupied_end_disparity_px};
    const ModuleReport::RangeEnds ends = m.RangeEndsReached();
    mj["range_end_reached"] = ends.near && ends.far ? "both" : ends.near ? "near" : ends.far ? "far" : "none";
    mj["lit_pixels_by_status"] = nlohmann::json::object();
    for (size_t k = 0; k < m.lit_by_status.size(); ++k)
      if (m.lit_by_status[k] > 0) mj["lit_pixels_by_status"][PixelStatusName(PixelStatus(k))] = m.lit_by_status[k];
    for (const auto& [step, ms] : m.times_ms) mj["time_ms"][step] = ms;
    if (m.surface_fit)
      mj["surface_fit"] = {{"window_px", {2 * m.surface_fit->half_width_px + 1, 2 * m.surface_fit->half_height_px + 1}},
                           {"median_misfit_px", m.surface_fit->median_misfit_px},
                           {"pixels_fitted", m.surface_fit->replaced}};
    // Counted only where they tell why a module is empty (ModuleReport):
    // the left image's whole grid-lit area when none lies in the volume's
    // ROI, the right image's when the module kept no point.
    if (m.camera_lit_pixels >= 0) mj["left_camera_lit_pixels"] = m.camera_lit_pixels;
    if (m.right_camera_lit_pixels >= 0) mj["right_camera_lit_pixels"] = m.right_camera_lit_pixels;
    mj["row_drift"] = nullptr;
    if (m.row_drift.read)
      mj["row_drift"] = {{"row_offset_px", m.row_drift.row_offset_px},
                         {"standard_error_px", m.row_drift.standard_error_px},
                         {"components", m.row_drift.components},
                         {"pixels", m.row_drift.pixels},
                         {"warned", m.row_drift.warned}};
    j["modules"].push_back(mj);
    lit += m.lit_pixels;
    filled += m.lit_filled;
  }
  j["points"] = rec.cloud.size();
  j["filled_points"] = rec.filled_points;
  j["fill_rate"] = lit ? double(filled) / lit : 0.0;
  j["mesh_triangles"] = rec.mesh.triangles.size();
  for (const auto& [step, ms] : rec.times_ms) j["time_ms"][step] = ms;
  j["shape_fit"] = rec.shape_fit;
  return j;
}

nlohmann::json ErrorFiguresJson(const ErrorFigures& f) {
  const auto figure = [&](double x) { return f.points > 0 ? nlohmann::json(x) : nlohmann::json(nullptr); };
  return {{"points", f.points},
          {"mean_abs_mm", figure(f.mean_abs_mm)},
          {"mean_mm", figure(f.mean_mm)},
          {"std_mm", figure(f.std_mm)},
          {"rms_mm", figure(f.rms_mm)},
          {"p95_abs_mm", figure(f.p95_abs_mm)},
          {"max_abs_mm", figure(f.max_abs_mm)},
          {"within_0_5_mm", figure(f.within_0_5_mm)}};
}

std::string ErrorText(const ErrorFigures& f, const char* unit) {
  if (f.points <= 0) return "no point";
  char buf[96];
  std::snprintf(buf, sizeof buf, "|e| %.4f std %.4f%s", f.mean_abs_mm, f.std_mm, unit);
  return buf;
}

std::string ErrorText(const nlohmann::json& figures, const char* unit) {
  ErrorFigures f;
  f.points = figures["points"].get<int>();
  if (f.points > 0) f.mean_abs_mm = figures["mean_abs_mm"].get<double>(), f.std_mm = figures["std_mm"].get<double>();
  return ErrorText(f, unit);
}

nlohmann::json FilledJson(const CloudScore& score) {
  nlohmann::json j = ErrorFiguresJson(score.filled);
  for (const FillBand& b : score.filled_by_distance) {
    nlohmann::json bj = ErrorFiguresJson(b.figures);
    bj["from_measured_mm"] = {b.from_mm, std::isfinite(b.to_mm) ? nlohmann::json(b.to_mm) : nlohmann::json(nullptr)};
    j["by_distance_to_measured"].push_back(bj);
  }
  return j;
}

}  // namespace stereorig
