// Runtime options: the hole-filling, surface-fit, line-index ambiguity, sub-pixel column-step, band-pass and
// strong-speckle keys are read, defaulted and checked (a bad value or an unknown key is an InputError naming it,
// as the options file spells it).
#include "reconstruct/runtime_options.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

// Each (YAML text, key) must fail to parse with an InputError that names the key.
template <size_t N>
void ExpectEachRejectedNamingItsKey(const std::pair<const char*, const char*> (&bad)[N]) {
  for (const auto& [text, key] : bad) {
    try {
      ParseRuntimeOptions(text, "bad.yaml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// Every key commented out: the built-in defaults, as with no file.
// A passive capture runs the same pipeline without the grid's own steps:
// exactly those four are off, everything else as given.
TEST(RuntimeOptions, PassiveOptionsTurnOffTheGridsStepsOnly) {
  RuntimeOptions active;
  active.object_size_mm = 60;
  active.match.min_zncc = 0.7;
  const RuntimeOptions passive = PassiveOptions(active);
  EXPECT_FALSE(passive.crop_to_lit_region);
  EXPECT_EQ(passive.match.min_distinctness, 0);
  EXPECT_FALSE(passive.match.grid_line.enabled);
  EXPECT_FALSE(passive.match.line_index.enabled);
  EXPECT_EQ(passive.object_size_mm, 60);
  EXPECT_EQ(passive.match.min_zncc, 0.7);
  EXPECT_EQ(passive.match.grow.enabled, active.match.grow.enabled);
  EXPECT_EQ(passive.match.speckle_window_px, active.match.speckle_window_px);
}

TEST(RuntimeOptions, AFileOfCommentsOnlyGivesTheDefaults) {
  const RuntimeOptions d;
  const RuntimeOptions o = ParseRuntimeOptions("# object_size_mm: 80\n# match:\n#   num_threads: 1\n", "c.yaml");
  EXPECT_EQ(o.object_size_mm, d.object_size_mm);
  EXPECT_EQ(o.volume_size_mm, d.volume_size_mm);
  EXPECT_EQ(o.match.num_threads, d.match.num_threads);
  EXPECT_EQ(o.match.min_zncc, d.match.min_zncc);
  EXPECT_EQ(o.shape_model, d.shape_model);
}

TEST(RuntimeOptions, ReadsAndChecksTheFillKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("shape_model: ellipsoid\n", "defaults.yaml");
  EXPECT_TRUE(d.fill_follow_residuals);
  EXPECT_EQ(d.fill_residual_length_mm, 0.0);
  const RuntimeOptions o = ParseRuntimeOptions(
      "shape_model: ellipsoid\nfill_follow_residuals: false\nfill_residual_length_mm: 12.5\n", "set.yaml");
  EXPECT_FALSE(o.fill_follow_residuals);
  EXPECT_EQ(o.fill_residual_length_mm, 12.5);
  const std::pair<const char*, const char*> bad[] = {{"fill_residual_length_mm: 0.5\n", "fill_residual_length_mm"},
                                                     {"fill_residual_length_mm: -3\n", "fill_residual_length_mm"},
                                                     {"fill_follow_residuals: maybe\n", "fill_follow_residuals"},
                                                     {"fill_follow_residual: true\n", "fill_follow_residual"}};
  ExpectEachRejectedNamingItsKey(bad);
}

TEST(RuntimeOptions, ReadsAndChecksTheSurfaceFitKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml");
  EXPECT_TRUE(d.match.surface_fit.enabled);
  EXPECT_EQ(d.match.surface_fit.half_width_px, 10);
  EXPECT_EQ(d.match.surface_fit.half_height_px, 5);
  EXPECT_EQ(d.match.surface_fit.reference_misfit_px, 0.2);
  const RuntimeOptions o = ParseRuntimeOptions(
      "match:\n  surface_fit: false\n  surface_fit_half_width_px: 12\n  surface_fit_half_height_px: 6\n"
      "  surface_fit_max_variance_growth: 2\n  surface_fit_max_misfit_ratio: 3\n"
      "  surface_fit_reference_misfit_px: 0\n",
      "set.yaml");
  EXPECT_FALSE(o.match.surface_fit.enabled);
  EXPECT_EQ(o.match.surface_fit.half_width_px, 12);
  EXPECT_EQ(o.match.surface_fit.half_height_px, 6);
  EXPECT_EQ(o.match.surface_fit.max_variance_growth, 2.0);
  EXPECT_EQ(o.match.surface_fit.max_misfit_ratio, 3.0);
  EXPECT_EQ(o.match.surface_fit.reference_misfit_px, 0.0);
  const std::pair<const char*, const char*> bad[] = {
      {"match:\n  surface_fit_half_width_px: 1\n", "surface_fit_half_width_px"},
      {"match:\n  surface_fit_half_height_px: 0\n", "surface_fit_half_height_px"},
      {"match:\n  surface_fit_max_variance_growth: 0.5\n", "surface_fit_max_variance_growth"},
      {"match:\n  surface_fit_max_misfit_ratio: 0\n", "surface_fit_max_misfit_ratio"},
      {"match:\n  surface_fit_reference_misfit_px: -0.1\n", "surface_fit_reference_misfit_px"},
      {"match:\n  surface_fit_reference_misfit_px: 11\n", "surface_fit_reference_misfit_px"},
      {"match:\n  surface_fits: true\n", "surface_fits"}};
  ExpectEachRejectedNamingItsKey(bad);
}

TEST(RuntimeOptions, ReadsAndChecksTheLineIndexAmbiguityKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml");
  EXPECT_EQ(d.match.line_index.footprint_gap_px, 8);
  EXPECT_EQ(d.match.line_index.ambiguity_sigmas, 1.0);
  const RuntimeOptions o =
      ParseRuntimeOptions("match:\n  line_index_footprint_gap_px: 0\n  line_index_ambiguity_sigmas: 2.5\n", "set.yaml");
  EXPECT_EQ(o.match.line_index.footprint_gap_px, 0);
  EXPECT_EQ(o.match.line_index.ambiguity_sigmas, 2.5);
  const std::pair<const char*, const char*> bad[] = {
      {"match:\n  line_index_footprint_gap_px: 17\n", "line_index_footprint_gap_px"},
      {"match:\n  line_index_footprint_gap_px: -1\n", "line_index_footprint_gap_px"},
      {"match:\n  line_index_ambiguity_sigmas: -0.5\n", "line_index_ambiguity_sigmas"},
      {"match:\n  line_index_ambiguity_sigma: 1\n", "line_index_ambiguity_sigma"}};
  ExpectEachRejectedNamingItsKey(bad);
}

TEST(RuntimeOptions, ReadsAndChecksTheSubpixelColumnStep) {
  EXPECT_EQ(ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml").match.subpixel_column_step, 1);
  EXPECT_EQ(ParseRuntimeOptions("match:\n  subpixel_column_step: 3\n", "set.yaml").match.subpixel_column_step, 3);
  const std::pair<const char*, const char*> bad[] = {{"match:\n  subpixel_column_step: 0\n", "subpixel_column_step"},
                                                     {"match:\n  subpixel_column_step: 5\n", "subpixel_column_step"},
                                                     {"match:\n  subpixel_column_step: 1.5\n", "subpixel_column_step"},
                                                     {"match:\n  subpixel_column_steps: 2\n", "subpixel_column_steps"}};
  ExpectEachRejectedNamingItsKey(bad);
}

TEST(RuntimeOptions, ReadsAndChecksTheSpeckleAlongSlopesKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml");
  EXPECT_FALSE(d.match.speckle_along_slopes);
  EXPECT_TRUE(d.match.final_speckle_along_slopes);
  EXPECT_TRUE(ParseRuntimeOptions("match:\n  speckle_along_slopes: true\n", "set.yaml").match.speckle_along_slopes);
  EXPECT_FALSE(ParseRuntimeOptions("match:\n  final_speckle_along_slopes: false\n", "set.yaml")
                   .match.final_speckle_along_slopes);
  const std::pair<const char*, const char*> bad[] = {
      {"match:\n  speckle_along_slopes: maybe\n", "speckle_along_slopes"},
      {"match:\n  speckle_along_slope: true\n", "speckle_along_slope"},
      {"match:\n  final_speckle_along_slopes: 2\n", "final_speckle_along_slopes"}};
  ExpectEachRejectedNamingItsKey(bad);
}

TEST(RuntimeOptions, ReadsAndChecksTheFreeSpaceKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml");
  EXPECT_TRUE(d.free_space_test);
  EXPECT_EQ(d.free_space.margin_px, 4.0);
  EXPECT_EQ(d.free_space.window_radius_px, 2);
  EXPECT_EQ(d.free_space.min_support, 3);
  EXPECT_EQ(d.free_space.min_facing_cos, 0.26);
  EXPECT_EQ(d.free_space.surface_fraction, 0.8);
  const RuntimeOptions o = ParseRuntimeOptions(
      "free_space_test: false\nfree_space_margin_px: 6\nfree_space_window_radius_px: 1\nfree_space_min_support: 5\n"
      "free_space_min_facing_cos: 0.5\nfree_space_surface_fraction: 1\n",
      "set.yaml");
  EXPECT_FALSE(o.free_space_test);
  EXPECT_EQ(o.free_space.margin_px, 6.0);
  EXPECT_EQ(o.free_space.window_radius_px, 1);
  EXPECT_EQ(o.free_space.min_support, 5);
  EXPECT_EQ(o.free_space.min_facing_cos, 0.5);
  EXPECT_EQ(o.free_space.surface_fraction, 1.0);
  const std::pair<const char*, const char*> bad[] = {
      {"free_space_test: maybe\n", "free_space_test"},
      {"free_space_tests: true\n", "free_space_tests"},
      {"free_space_margin_px: 0\n", "free_space_margin_px"},
      {"free_space_margin_px: 101\n", "free_space_margin_px"},
      {"free_space_window_radius_px: -1\n", "free_space_window_radius_px"},
      {"free_space_window_radius_px: 6\n", "free_space_window_radius_px"},
      {"free_space_min_support: 0\n", "free_space_min_support"},
      {"free_space_min_support: 26\n", "free_space_min_support"},  // the default 5x5 window has 25 pixels
      {"free_space_min_facing_cos: 1\n", "free_space_min_facing_cos"},
      {"free_space_min_facing_cos: -0.1\n", "free_space_min_facing_cos"},
      {"free_space_surface_fraction: 0\n", "free_space_surface_fraction"},
      {"free_space_surface_fraction: 1.01\n", "free_space_surface_fraction"}};
  ExpectEachRejectedNamingItsKey(bad);
}

TEST(RuntimeOptions, ReadsAndChecksTheBandPassKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml");
  EXPECT_EQ(d.match.band_sgm_paths, 4);
  EXPECT_EQ(d.match.band_row_step, 1);
  const RuntimeOptions o =
      ParseRuntimeOptions("match:\n  band_sgm_paths: 3\n  band_row_step: 2\n  sgm_paths: 4\n", "set.yaml");
  EXPECT_EQ(o.match.band_sgm_paths, 3);
  EXPECT_EQ(o.match.band_row_step, 2);
  EXPECT_EQ(o.match.sgm.num_paths, 4);  // the full-resolution search keeps its own
  const std::pair<const char*, const char*> bad[] = {
      {"match:\n  band_sgm_paths: 2\n", "band_sgm_paths"},
      {"match:\n  band_row_step: 0\n", "band_row_step"},
      {"match:\n  band_row_step: 3\n", "band_row_step"},
      {"match:\n  band_row_step: 2\n  guided_radius_px: 15\n", "band_row_step"},
      {"match:\n  band_row_steps: 2\n", "band_row_steps"}};
  ExpectEachRejectedNamingItsKey(bad);
}

// A bad value under match: is named match.<key>, the key the file holds,
// also where the check sits in a nested options struct (the SGM's and the
// sub-pixel fit's once said sgm.p2, subpixel.half_width_px: keys no
// options file has).
TEST(RuntimeOptions, AMatchValueOutOfRangeIsNamedAsTheFileNamesIt) {
  const std::pair<const char*, const char*> bad[] = {
      {"match:\n  sgm_p1: 0\n", "match.sgm_p1:"},
      {"match:\n  sgm_p1: 10\n  sgm_p2: 5\n", "match.sgm_p2:"},
      {"match:\n  sgm_paths: 8\n", "match.sgm_paths:"},
      {"match:\n  uniqueness_percent: 60\n", "match.uniqueness_percent:"},
      {"match:\n  lr_max_diff_px: -1\n", "match.lr_max_diff_px:"},
      {"match:\n  subpixel_half_width_px: 0\n", "match.subpixel_half_width_px:"},
      {"match:\n  subpixel_half_height_px: 31\n", "match.subpixel_half_height_px:"},
      {"match:\n  min_zncc: 1.0\n", "match.min_zncc:"},
      {"match:\n  range_margin_px: -50\n", "match.range_margin_px:"},
      {"match:\n  range_margin_px: 257\n", "match.range_margin_px:"}};
  ExpectEachRejectedNamingItsKey(bad);
  EXPECT_EQ(ParseRuntimeOptions("match:\n  range_margin_px: 0\n", "ok.yaml").match.range_margin_px, 0);
}

TEST(RuntimeOptions, ReadsAndChecksTheStrongSpeckleKeys) {
  const RuntimeOptions d = ParseRuntimeOptions("min_confidence: 0.5\n", "defaults.yaml");
  EXPECT_EQ(d.match.grow.noise_zncc_factor, 4.0);
  EXPECT_EQ(d.match.grow.noise_min_zncc, 0.6);
  EXPECT_EQ(d.match.line_index.area_per_sample_px, 81);
  EXPECT_EQ(d.match.line_index.seam_spread_px, 3.0);
  EXPECT_TRUE(d.match.line_index.lattice_sampling);
  const RuntimeOptions o = ParseRuntimeOptions(
      "match:\n  grow_noise_zncc_factor: 0\n  grow_noise_min_zncc: 0.5\n  line_index_area_per_sample_px: 0\n"
      "  line_index_seam_spread_px: 1\n  line_index_lattice_sampling: false\n",
      "set.yaml");
  EXPECT_EQ(o.match.grow.noise_zncc_factor, 0.0);
  EXPECT_EQ(o.match.grow.noise_min_zncc, 0.5);
  EXPECT_EQ(o.match.line_index.area_per_sample_px, 0);
  EXPECT_EQ(o.match.line_index.seam_spread_px, 1.0);
  EXPECT_FALSE(o.match.line_index.lattice_sampling);
  const std::pair<const char*, const char*> bad[] = {
      {"match:\n  line_index_lattice_sampling: sometimes\n", "line_index_lattice_sampling"},
      {"match:\n  line_index_area_per_sample_px: 80\n", "line_index_area_per_sample_px"},
      {"match:\n  grow_noise_zncc_factor: -1\n", "grow_noise_zncc_factor"},
      {"match:\n  grow_noise_zncc_factor: 21\n", "grow_noise_zncc_factor"},
      {"match:\n  grow_noise_min_zncc: 1\n", "grow_noise_min_zncc"},
      {"match:\n  line_index_area_per_sample_px: -1\n", "line_index_area_per_sample_px"},
      {"match:\n  line_index_seam_spread_px: 0\n", "line_index_seam_spread_px"},
      {"match:\n  line_index_seam_spread_px: 5\n", "line_index_seam_spread_px"}};
  ExpectEachRejectedNamingItsKey(bad);
}

// The message of the InputError `text` is refused with ("" if accepted).
std::string RefusalOf(const std::string& text, const std::string& where = "o.yaml") {
  try {
    ParseRuntimeOptions(text, where);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The docs name the matcher's keys `match.min_zncc`; written so, the key was
// refused as "unknown key" with no word of the nesting. Still refused, now
// with how to write it.
TEST(RuntimeOptions, AMatchKeyWrittenDottedIsRefusedWithHowItNests) {
  EXPECT_EQ(RefusalOf("match.min_zncc: 0.7\n"),
            "o.yaml: match.min_zncc: unknown key: the matcher's keys nest under a `match:` mapping: write it as "
            "`match:` then, on the next line, `  min_zncc: ...`");
  EXPECT_EQ(ParseRuntimeOptions("match:\n  min_zncc: 0.7\n", "o.yaml").match.min_zncc, 0.7);
}

// Values no rig can use were taken: object_size_mm 0.001 wrote an empty
// cloud (exit 0), 1e9 and fill_spacing_mm 1e6 turned their steps off
// unsaid, lit_contrast_dn 300 lit nothing (an 8-bit window's std is at
// most 127.5). Each is refused naming the file and key; the bounds
// themselves are taken.
TEST(RuntimeOptions, ValuesPastWhatTheRigCanMeasureAreRefused) {
  for (const char* bad :
       {"object_size_mm: 0.001\n", "object_size_mm: 1e9\n", "object_size_mm: 2346\n", "lit_contrast_dn: 300\n",
        "lit_contrast_dn: 127.5\n", "fill_spacing_mm: 1e6\n", "object_size_mm: 50\nfill_spacing_mm: 51\n"}) {
    const std::string key = std::string(bad).substr(std::string(bad).rfind('\n', std::string(bad).size() - 2) + 1);
    const std::string says = "o.yaml: " + key.substr(0, key.find(':')) + ": must be in ";
    EXPECT_EQ(RefusalOf(bad).rfind(says, 0), 0u) << bad << " -> " << RefusalOf(bad);
  }
  // The default volume's diagonal: sqrt(150^2 + 150^2 + 100^2) = 234.5 mm,
  // ten times it 2345 mm.
  EXPECT_EQ(RefusalOf("object_size_mm: 1\nfill_spacing_mm: 1\n"), "");
  EXPECT_EQ(RefusalOf("object_size_mm: 2345\nlit_contrast_dn: 127\n"), "");
  // A small volume with the default object size (100 mm, over its 94 mm
  // diagonal): the user set no object_size_mm, and none is refused (a second
  // reading: the bound was the diagonal itself).
  EXPECT_EQ(RefusalOf("volume_size_mm: [60, 60, 40]\n"), "");
  EXPECT_EQ(RefusalOf("object_size_mm: 400\nvolume_size_mm: [300, 300, 200]\n"), "");
  // A volume smaller than the smallest object (a diagonal under 1 mm: sides
  // given in m, the default's [0.15, 0.15, 0.1] a 0.235 mm diagonal) is
  // named as the volume, not as the object size it leaves no room for
  // ("object_size_mm: must be in [1, 2.3] mm", a key the user never set).
  EXPECT_EQ(RefusalOf("volume_size_mm: [0.15, 0.15, 0.1]\n"),
            "o.yaml: volume_size_mm: its diagonal, 0.235 mm, is under the smallest object (object_size_mm: at least "
            "1 mm): its sides are in mm");
  EXPECT_EQ(RefusalOf("volume_size_mm: [0.015, 0.015, 0.01]\n"),
            "o.yaml: volume_size_mm: its diagonal, 0.0235 mm, is under the smallest object (object_size_mm: at least "
            "1 mm): its sides are in mm");
  // A 1 m belt's volume typed in metres (a 1.5 mm diagonal) with the default
  // object size (100 mm) named object_size_mm too: named as the volume.
  EXPECT_EQ(RefusalOf("volume_size_mm: [1, 1, 0.5]\n"),
            "o.yaml: volume_size_mm: its diagonal, 1.5 mm, is under a tenth of object_size_mm (100 mm; 100 unless "
            "set): its sides are in mm (for objects that small, set object_size_mm too)");
  // A volume over 10 mm across: the object size is the one named (1e5 for 100 mm in um).
  EXPECT_EQ(RefusalOf("object_size_mm: 100000\n").rfind("o.yaml: object_size_mm: must be in [1, 2345", 0), 0u);
  // Just over 1 mm (sqrt(3) x 0.6 = 1.04 mm) holds the 1 mm object.
  EXPECT_EQ(RefusalOf("volume_size_mm: [0.6, 0.6, 0.6]\nobject_size_mm: 1\n"), "");
}

// working_distance_mm only places the default volume centre: given with
// volume_center_mm it was silently ignored (5000 mm beside a centre at 200
// mm, accepted). The pair is refused naming the file and both keys; each
// alone is read.
TEST(RuntimeOptions, AWorkingDistanceBesideAVolumeCentreIsRefused) {
  EXPECT_EQ(RefusalOf("working_distance_mm: 5000\nvolume_center_mm: [0, 0, 200]\n"),
            "o.yaml: working_distance_mm and volume_center_mm are both given: working_distance_mm only places the "
            "default volume centre, which volume_center_mm replaces; keep one of them");
  EXPECT_EQ(ParseRuntimeOptions("working_distance_mm: 5000\n", "o.yaml").working_distance_mm, 5000);
  EXPECT_EQ(ParseRuntimeOptions("volume_center_mm: [0, 0, 200]\n", "o.yaml").volume_center_mm,
            Eigen::Vector3d(0, 0, 200));
}

// yaml-cpp reads the first document only: a second one's keys, typos too,
// were never checked. The options file is one mapping: a second document
// is refused naming the file and the line it starts on; a lone trailing
// `---` (an empty document) is no setting and passes.
TEST(RuntimeOptions, ASecondYamlDocumentIsRefused) {
  EXPECT_EQ(RefusalOf("object_size_mm: 50\n---\nbogus_key: 1\n"),
            "o.yaml: line 3: a second YAML document (after `---`): the file is one mapping; remove the `---`, or "
            "merge its keys into the first document");
  EXPECT_NE(RefusalOf("object_size_mm: 50\n---\n[: bad\n").find("o.yaml: not valid YAML"), std::string::npos);
  EXPECT_EQ(RefusalOf("---\nobject_size_mm: 50\n"), "");
  EXPECT_EQ(RefusalOf("object_size_mm: 50\n---\n"), "");
}

// docs/formats.md: a file with every key commented out reads as the
// defaults. `match:` with every key under it commented out is YAML's null,
// and was refused ("match: expected a mapping"); it reads as a `match`
// section with no keys: the matcher's defaults.
TEST(RuntimeOptions, AMatchSectionWithEveryKeyCommentedOutIsTheDefaults) {
  const RuntimeOptions o = ParseRuntimeOptions("object_size_mm: 60\nmatch:\n#  min_zncc: 0.7\n", "cm.yaml");
  EXPECT_EQ(o.object_size_mm, 60);
  EXPECT_EQ(o.match.min_zncc, MatchOptions{}.min_zncc);
  EXPECT_EQ(ParseRuntimeOptions("match: ~\n", "cm.yaml").match.min_zncc, MatchOptions{}.min_zncc);
  EXPECT_EQ(RefusalOf("match: 3\n"), "o.yaml: match: expected a mapping");
}

// A one-row vernier window (line_index_window_half_height_px 0) cannot read
// the row offset the line index tests, and was accepted: every point of 8
// of the demo's 10 modules went (wrong_line). Refused, saying why; 1, the
// smallest that works on the demo scenes, is read.
TEST(RuntimeOptions, AOneRowVernierWindowIsRefused) {
  EXPECT_EQ(RefusalOf("match:\n  line_index_window_half_height_px: 0\n"),
            "o.yaml: match.line_index_window_half_height_px: must be in [1, 30] (3 to 61 rows): the vernier fits a "
            "row offset between the views, which a window of one row (0) cannot read");
  EXPECT_EQ(ParseRuntimeOptions("match:\n  line_index_window_half_height_px: 1\n", "o.yaml")
                .match.line_index.window_half_height_px,
            1);
}

}  // namespace
}  // namespace stereorig
