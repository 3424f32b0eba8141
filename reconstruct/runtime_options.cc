#include "reconstruct/runtime_options.h"

#include <cstdio>
#include <string>
#include <vector>

#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/yaml_reader.h"

namespace stereorig {

ShapeModel ParseShapeModel(const std::string& name, const std::string& where) {
  if (name == "none") return ShapeModel::kNone;
  if (name == "sphere") return ShapeModel::kSphere;
  if (name == "cylinder") return ShapeModel::kCylinder;
  if (name == "ellipsoid") return ShapeModel::kEllipsoid;
  throw InputError(where, "unknown shape model '" + name + "' (none, sphere, cylinder or ellipsoid)");
}

const char* ShapeModelName(ShapeModel model) {
  switch (model) {
    case ShapeModel::kSphere:
      return "sphere";
    case ShapeModel::kCylinder:
      return "cylinder";
    case ShapeModel::kEllipsoid:
      return "ellipsoid";
    default:
      return "none";
  }
}

void RuntimeOptions::Check() const {
  if (volume_center_mm && !volume_center_mm->allFinite()) throw InputError("volume_center_mm", "must be finite");
  if (!(volume_size_mm.minCoeff() > 0)) throw InputError("volume_size_mm", "every side must be > 0 mm");
  if (!(working_distance_mm > 0)) throw InputError("working_distance_mm", "must be > 0 mm");
  // An object under 1 mm spans ~5 px at the default 200 mm (~0.2 mm a
  // pixel): less than one laser-grid period (8 px), nothing to match; every
  // point would be dropped (0.001 wrote an empty cloud, exit 0). Above, an
  // object larger than the volume is harmless (the volume's own filter cuts
  // every point to it first, so this one never bites), and the default 100
  // mm exceeds a small volume's diagonal (60 x 60 x 40 mm: 94 mm), so only
  // a size no object in the volume could have is refused: ten times its
  // diagonal, a unit slip (um for mm, or 1e9 for "off").
  const double volume_diagonal_mm = volume_size_mm.norm();
  // A volume whose diagonal is under 1 mm holds no object of the smallest
  // size (its sides typed in metres: the default's [0.15, 0.15, 0.1] is a
  // 0.235 mm diagonal): the volume is wrong, not object_size_mm ("must be in
  // [1, 2.3] mm" named a key the user had not set).
  if (!(volume_diagonal_mm >= 1)) {
    char why[160];
    std::snprintf(why, sizeof why,
                  "its diagonal, %.3g mm, is under the smallest object (object_size_mm: at least 1 mm): its sides "
                  "are in mm",
                  volume_diagonal_mm);
    throw InputError("volume_size_mm", why);
  }
  // A volume under 10 mm across that the object size outgrows is a volume
  // typed in metres (a 1 m belt's [1, 1, 0.5], 1.5 mm) far more likely than
  // objects of that size: named as the volume, object_size_mm (100 mm unless
  // set) said beside it. Above 10 mm, the object size is the one to check.
  if (object_size_mm > 10 * volume_diagonal_mm && volume_diagonal_mm < 10) {
    char why[240];
    std::snprintf(why, sizeof why,
                  "its diagonal, %.3g mm, is under a tenth of object_size_mm (%g mm; 100 unless set): its sides are "
                  "in mm (for objects that small, set object_size_mm too)",
                  volume_diagonal_mm, object_size_mm);
    throw InputError("volume_size_mm", why);
  }
  if (!(object_size_mm >= 1 && object_size_mm <= 10 * volume_diagonal_mm)) {
    char range[128];
    std::snprintf(range, sizeof range, "must be in [1, %.1f] mm (ten times the measurement volume's diagonal)",
                  10 * volume_diagonal_mm);
    throw InputError("object_size_mm", range);
  }
  // A 9x9 window of 8-bit grey levels has a std of at most 127.5 (half its
  // pixels 0, half 255): a threshold at or above it lights nothing.
  if (!(lit_contrast_dn > 0 && lit_contrast_dn < 127.5))
    throw InputError("lit_contrast_dn", "must be in (0, 127.5) grey levels (an 8-bit window's std cannot reach 127.5)");
  if (!(min_confidence >= 0 && min_confidence <= 1)) throw InputError("min_confidence", "must be in [0, 1]");
  if (normal_step_px < 1 || normal_step_px > 10) throw InputError("normal_step_px", "must be in [1, 10]");
  if (!(mesh_max_edge_mm > 0)) throw InputError("mesh_max_edge_mm", "must be > 0");
  // Filled samples farther apart than the object's largest dimension leave
  // at most one on it: nothing filled.
  if (!(fill_spacing_mm > 0.05 && fill_spacing_mm <= object_size_mm))
    throw InputError("fill_spacing_mm", "must be in (0.05, object_size_mm] mm (a wider spacing fills nothing)");
  if (!(fill_residual_length_mm == 0 || (fill_residual_length_mm >= 1 && fill_residual_length_mm <= 1000)))
    throw InputError("fill_residual_length_mm", "must be 0 (chosen from the data) or in [1, 1000] mm");
  if (!(free_space.margin_px > 0 && free_space.margin_px <= 100))
    throw InputError("free_space_margin_px", "must be in (0, 100] px");
  if (free_space.window_radius_px < 0 || free_space.window_radius_px > 5)
    throw InputError("free_space_window_radius_px", "must be in [0, 5] px");
  {
    const int window = (2 * free_space.window_radius_px + 1) * (2 * free_space.window_radius_px + 1);
    if (free_space.min_support < 1 || free_space.min_support > window)
      throw InputError("free_space_min_support",
                       "must be in [1, " + std::to_string(window) + "] (the pixels of the window)");
  }
  if (!(free_space.min_facing_cos >= 0 && free_space.min_facing_cos < 1))
    throw InputError("free_space_min_facing_cos", "must be in [0, 1)");
  if (!(free_space.surface_fraction > 0 && free_space.surface_fraction <= 1))
    throw InputError("free_space_surface_fraction", "must be in (0, 1]");
  try {
    match.Check();
  } catch (const InputError& e) {  // named as the options file names it: match.<key>
    throw InputError("match." + e.where(), e.problem());
  }
}

namespace {

RuntimeOptions FromYaml(YamlMap& y) {
  RuntimeOptions o;
  if (y.Has("volume_center_mm")) {
    const auto v = y.GetDoubles("volume_center_mm", 3);
    o.volume_center_mm = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (y.Has("volume_size_mm")) {
    const auto v = y.GetDoubles("volume_size_mm", 3);
    o.volume_size_mm = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  // working_distance_mm only places the default centre: beside
  // volume_center_mm it was read and then ignored, unsaid, where a user
  // meant one of the two. Refused, naming both, as a key that does not
  // apply is elsewhere.
  if (y.Has("working_distance_mm") && y.Has("volume_center_mm"))
    throw InputError(y.file(),
                     "working_distance_mm and volume_center_mm are both given: working_distance_mm only places the "
                     "default volume centre, which volume_center_mm replaces; keep one of them");
  y.Read("working_distance_mm", &o.working_distance_mm);
  y.Read("object_size_mm", &o.object_size_mm);
  y.Read("crop_to_lit_region", &o.crop_to_lit_region);
  y.Read("lit_contrast_dn", &o.lit_contrast_dn);
  y.Read("min_confidence", &o.min_confidence);
  y.Read("normal_step_px", &o.normal_step_px);
  y.Read("mesh_max_edge_mm", &o.mesh_max_edge_mm);
  o.shape_model = ParseShapeModel(y.GetString("shape_model", "none"), y.Where("shape_model"));
  y.Read("fill_spacing_mm", &o.fill_spacing_mm);
  y.Read("fill_follow_residuals", &o.fill_follow_residuals);
  y.Read("fill_residual_length_mm", &o.fill_residual_length_mm);
  y.Read("parallel_modules", &o.parallel_modules);
  y.Read("free_space_test", &o.free_space_test);
  y.Read("free_space_margin_px", &o.free_space.margin_px);
  y.Read("free_space_window_radius_px", &o.free_space.window_radius_px);
  y.Read("free_space_min_support", &o.free_space.min_support);
  y.Read("free_space_min_facing_cos", &o.free_space.min_facing_cos);
  y.Read("free_space_surface_fraction", &o.free_space.surface_fraction);
  if (y.Has("match")) {
    YamlMap m = y.GetMapOrEmpty("match");  // `match:` with every key commented out: the defaults
    MatchOptions& mo = o.match;
    mo.matcher = ParseMatcherKind(m.GetString("matcher", "census_sgm"), m.Where("matcher"));
    m.Read("pyramid_levels", &mo.pyramid_levels);
    m.Read("refine_radius_px", &mo.refine_radius_px);
    m.Read("sgm_p1", &mo.sgm.p1);
    m.Read("sgm_p2", &mo.sgm.p2);
    m.Read("sgm_paths", &mo.sgm.num_paths);
    m.Read("uniqueness_percent", &mo.sgm.uniqueness_percent);
    m.Read("lr_max_diff_px", &mo.sgm.lr_max_diff_px);
    m.Read("intensity_refinement", &mo.intensity_refinement);
    m.Read("subpixel_half_width_px", &mo.subpixel.half_width_px);
    m.Read("subpixel_half_height_px", &mo.subpixel.half_height_px);
    m.Read("subpixel_dense", &mo.subpixel_dense);
    m.Read("subpixel_column_step", &mo.subpixel_column_step);
    m.Read("min_zncc", &mo.min_zncc);
    m.Read("max_plane_deviation_px", &mo.max_plane_deviation_px);
    m.Read("narrow_range", &mo.narrow_range);
    m.Read("range_margin_px", &mo.range_margin_px);
    m.Read("guided_radius_px", &mo.guided_radius_px);
    m.Read("band_sgm_paths", &mo.band_sgm_paths);
    m.Read("band_row_step", &mo.band_row_step);
    m.Read("census_half_width_px", &mo.census_half_width_px);
    m.Read("census_half_height_px", &mo.census_half_height_px);
    m.Read("min_texture_dn", &mo.min_texture_dn);
    m.Read("speckle_window_px", &mo.speckle_window_px);
    m.Read("speckle_range_px", &mo.speckle_range_px);
    m.Read("speckle_along_slopes", &mo.speckle_along_slopes);
    m.Read("final_speckle_along_slopes", &mo.final_speckle_along_slopes);
    m.Read("occlusion_margin_px", &mo.occlusion_margin_px);
    m.Read("right_view_edge_test", &mo.right_view_edge_test);
    m.Read("grid_line_test", &mo.grid_line.enabled);
    m.Read("grid_line_min_prominence_dn", &mo.grid_line.min_prominence_dn);
    m.Read("grid_line_radius_px", &mo.grid_line.radius_px);
    m.Read("grid_line_min_ridge_px", &mo.grid_line.min_ridge_px);
    m.Read("surface_fit", &mo.surface_fit.enabled);
    m.Read("surface_fit_half_width_px", &mo.surface_fit.half_width_px);
    m.Read("surface_fit_half_height_px", &mo.surface_fit.half_height_px);
    m.Read("surface_fit_max_variance_growth", &mo.surface_fit.max_variance_growth);
    m.Read("surface_fit_max_misfit_ratio", &mo.surface_fit.max_misfit_ratio);
    m.Read("surface_fit_reference_misfit_px", &mo.surface_fit.reference_misfit_px);
    m.Read("sgbm_block_size", &mo.sgbm_block_size);
    m.Read("num_threads", &mo.num_threads);
    m.Read("line_index", &mo.line_index.enabled);
    m.Read("line_index_max_shift_px", &mo.line_index.max_shift_px);
    m.Read("line_index_min_component_px", &mo.line_index.min_component_px);
    m.Read("line_index_samples", &mo.line_index.samples);
    m.Read("line_index_lattice_sampling", &mo.line_index.lattice_sampling);
    m.Read("line_index_min_seam_px", &mo.line_index.min_seam_px);
    m.Read("line_index_max_seam_gap_px", &mo.line_index.max_seam_gap_px);
    m.Read("line_index_seam_spread_px", &mo.line_index.seam_spread_px);
    m.Read("line_index_window_half_height_px", &mo.line_index.window_half_height_px);
    m.Read("line_index_max_row_offset_px", &mo.line_index.max_row_offset_px);
    m.Read("line_index_min_row_offset_step_px", &mo.line_index.min_row_offset_step_px);
    m.Read("line_index_drop_row_offset_px", &mo.line_index.drop_row_offset_px);
    m.Read("line_index_footprint_gap_px", &mo.line_index.footprint_gap_px);
    m.Read("line_index_area_per_sample_px", &mo.line_index.area_per_sample_px);
    m.Read("line_index_ambiguity_sigmas", &mo.line_index.ambiguity_sigmas);
    m.Read("grow", &mo.grow.enabled);
    m.Read("grow_max_deviation_px", &mo.grow.max_deviation_px);
    m.Read("grow_plane_radius_px", &mo.grow.plane_radius_px);
    m.Read("grow_max_tries", &mo.grow.max_tries);
    m.Read("grow_shifted_windows", &mo.grow.shifted_windows);
    m.Read("grow_shifted_min_foreshortening", &mo.grow.shifted_min_foreshortening);
    m.Read("grow_shifted_min_zncc", &mo.grow.shifted_min_zncc);
    m.Read("grow_noise_zncc_factor", &mo.grow.noise_zncc_factor);
    m.Read("grow_noise_min_zncc", &mo.grow.noise_min_zncc);
    m.Read("grow_shifted_enclosed_min_zncc", &mo.grow.shifted_enclosed_min_zncc);
    m.Read("grow_oblique", &mo.grow.oblique.enabled);
    m.Read("grow_oblique_min_foreshortening", &mo.grow.oblique.min_foreshortening);
    m.Read("grow_oblique_psf_sigma_px", &mo.grow.oblique.psf_sigma_px);
    m.Read("grow_oblique_max_half_width_px", &mo.grow.oblique.max_half_width_px);
    m.Read("min_distinctness", &mo.min_distinctness);
    m.Read("grid_half_period_px", &mo.grid_half_period_px);
    m.Finish();
  }
  // The docs name the matcher's keys `match.min_zncc`; written so, YAML
  // reads one top-level key with a dot in its name. Say how it nests, not
  // only "unknown key" (a hint: it is still refused).
  for (const std::string& key : y.Keys())
    if (key.rfind("match.", 0) == 0 && key.size() > 6)
      throw InputError(y.Where(key),
                       "unknown key: the matcher's keys nest under a `match:` mapping: write it as "
                       "`match:` then, on the next line, `  " +
                           key.substr(6) + ": ...`");
  y.Finish();
  try {
    o.Check();
  } catch (const InputError& e) {
    throw InputError(y.file(), e.what());
  }
  return o;
}

}  // namespace

RuntimeOptions PassiveOptions(RuntimeOptions active) {
  active.crop_to_lit_region = false;
  active.match.min_distinctness = 0;
  active.match.grid_line.enabled = false;
  active.match.line_index.enabled = false;
  return active;
}

bool IsPassive(const RuntimeOptions& options) {
  const RuntimeOptions passive = PassiveOptions(options);
  return options.crop_to_lit_region == passive.crop_to_lit_region &&
         options.match.min_distinctness == passive.match.min_distinctness &&
         options.match.grid_line.enabled == passive.match.grid_line.enabled &&
         options.match.line_index.enabled == passive.match.line_index.enabled;
}

RuntimeOptions ReadRuntimeOptions(const std::string& path) {
  // The text read once (a pipe too, as YamlMap::LoadFile reads), then parsed
  // as ParseRuntimeOptions parses it, so both refuse a second document.
  return ParseRuntimeOptions(ReadInputText(path), path);
}

RuntimeOptions ParseRuntimeOptions(const std::string& text, const std::string& where) {
  YamlMap y = YamlMap::LoadString(text, where);  // one document: a second is refused (yaml_reader.h)
  RuntimeOptions o = FromYaml(y);
  o.source = where;
  return o;
}

}  // namespace stereorig
