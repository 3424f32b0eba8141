// `stereorig verify`: VDI/VDE 2634-2 acceptance figures from reconstructions
// of a reference artifact, judged against the MPE under an ISO 14253-1
// decision rule (--decision-rule, default simple acceptance). Exit 0 all pass, 1 any
// judged position fails, 2 bad input or (with no failure) a position not
// judged (printed all the same; no report written).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/limit_text.h"
#include "apps/output_paths.h"
#include "apps/verify_help.h"
#include "apps/verify_positions.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "calib/json_text.h"
#include "reconstruct/metrology/artifact.h"
#include "reconstruct/metrology/ply_points.h"
#include "reconstruct/metrology/vdi2634.h"

namespace stereorig {

namespace {

// Where a figure's MPE comes from: the artifact file's mpe_mm, or the
// default (MaximumPermissibleErrors) where the file gives none.
const char* MpeSource(const Artifact& artifact, const std::string& figure) {
  return artifact.mpe.Given(figure) ? "certificate" : "default";
}

// judged: false for a position not judged, whose figures are reported with
// "pass": null.
nlohmann::json FigureJson(const Figure& f, bool judged, const Artifact& artifact) {
  judged = judged && f.judged;  // a figure left undetermined: its pass is not claimed
  nlohmann::json j = {{"name", f.name},     {"value_mm", f.value_mm},
                      {"mpe_mm", f.mpe_mm}, {"mpe_source", MpeSource(artifact, f.name)},
                      {"judged", judged},   {"pass", nullptr}};
  if (judged) j["pass"] = f.pass;
  if (f.standard_uncertainty_mm) j["standard_uncertainty_mm"] = *f.standard_uncertainty_mm;
  if (f.fit_standard_uncertainty_mm) j["fit_standard_uncertainty_mm"] = *f.fit_standard_uncertainty_mm;
  if (f.certificate_standard_uncertainty_mm) {
    j["certificate_standard_uncertainty_mm"] = *f.certificate_standard_uncertainty_mm;
  }
  // ISO 14253-1's zone of the figure with U = 2u (decision_rule.h); a figure
  // without u has neither, nor one whose u is a floor (not judged).
  if (const auto zone = f.zone(); zone && f.judged) {
    j["expanded_uncertainty_mm"] = f.ExpandedUncertaintyMm();
    j["zone"] = ConformanceZoneName(*zone);
  }
  return j;
}

// The zone's name and its condition, for the uncertainty line.
std::string ZoneText(ConformanceZone zone) {
  switch (zone) {
    case ConformanceZone::kConformance:
      return "conformance zone (|value| + 2u <= MPE)";
    case ConformanceZone::kUncertaintyRange:
      return "uncertainty range (within 2u of the MPE)";
    case ConformanceZone::kNonconformance:
      return "nonconformance zone (|value| - 2u > MPE)";
  }
  return "?";
}

// What each rule passes, for the table's heading.
const char* DecisionRuleText(DecisionRule rule) {
  switch (rule) {
    case DecisionRule::kSimpleAcceptance:
      return "simple acceptance: a figure passes if |value| <= MPE";
    case DecisionRule::kGuardedAcceptance:
      return "guarded acceptance: a figure passes only if |value| + 2u <= MPE (within it by its expanded "
             "uncertainty)";
    case DecisionRule::kGuardedRejection:
      return "guarded rejection: a figure fails only if |value| - 2u > MPE (beyond it by its expanded uncertainty)";
  }
  return "?";
}

// A figure's u and its parts: the fit's and the certificate's (U / k),
// combined in quadrature.
void PrintUncertainty(size_t position, const Figure& f, double coverage_factor) {
  if (!f.standard_uncertainty_mm) return;
  const double certificate_mm = f.certificate_standard_uncertainty_mm.value_or(0.0);
  char fit[64] = "no fit part: a range of residuals";  // P_F, F
  if (f.fit_standard_uncertainty_mm) std::snprintf(fit, sizeof fit, "fit %.4f mm", *f.fit_standard_uncertainty_mm);
  // Not judged: where u is a floor (the fit's part over the limit) no zone
  // is claimed; where the certificate's stated U puts it over, the zone is
  // the figure's, too wide to pass on.
  const std::string zone = f.judged                 ? ZoneText(*f.zone())
                           : f.uncertainty_is_floor ? "no zone: u over the limit is a floor, not the error"
                                                    : ZoneText(*f.zone()) + ", but u is over the limit: not judged";
  std::printf("%-8zu %s: u %.4f mm = %s (+) certificate %.4f mm (U %.4f mm / k %g); 2u %.4f mm: %s\n", position,
              f.name.c_str(), *f.standard_uncertainty_mm, fit, certificate_mm, certificate_mm * coverage_factor,
              coverage_factor, f.ExpandedUncertaintyMm(), zone.c_str());
}

// Each fitted sphere (1 for a sphere, 2 for a ball bar): its size, how much
// of it the points cover, how well they fit its diameter, and its form (on
// a ball bar, where a patch one grid period off on one ball shows).
nlohmann::json SpheresJson(const ArtifactEvaluation& e) {
  nlohmann::json spheres = nlohmann::json::array();
  for (size_t k = 0; k < e.sphere_centers_mm.size(); ++k) {
    const Eigen::Vector3d& c = e.sphere_centers_mm[k];
    spheres.push_back({{"center_mm", {c.x(), c.y(), c.z()}},
                       {"diameter_mm", e.sphere_diameters_mm[k]},
                       {"diameter_std_mm", e.sphere_diameter_std_mm[k]},
                       {"noise_variance_inflation", e.sphere_noise_variance_inflation[k]},
                       {"cap_half_angle_deg", e.sphere_cap_half_angles_deg[k]},
                       {"form_mm", e.sphere_form_mm[k]}});
  }
  return spheres;
}

void PrintSpheres(size_t position, const ArtifactEvaluation& e) {
  for (size_t k = 0; k < e.sphere_centers_mm.size(); ++k) {
    // The factor u carries for noise its neighbouring points share (a
    // matching window's): counted as independent, they gave a u ~8x too
    // small on the demo's clouds. Said where it is not 1.
    char shared[96] = "";
    if (e.sphere_noise_variance_inflation[k] > 1) {
      std::snprintf(shared, sizeof shared, " (x%.1f: neighbouring points share its noise)",
                    std::sqrt(e.sphere_noise_variance_inflation[k]));
    }
    // A sphere's form is its P_F: printed with the table's digits for it
    // (0.34153 there read 0.3415 here).
    const auto p_f = std::find_if(e.figures.begin(), e.figures.end(), [](const Figure& f) { return f.name == "P_F"; });
    const std::string form = e.type == ArtifactType::kSphere && p_f != e.figures.end()
                                 ? ValueBesideLimitText(e.sphere_form_mm[k], p_f->mpe_mm)
                                 : FixedText(e.sphere_form_mm[k], 4);
    std::printf(
        "%-8zu sphere %zu: diameter %.4f mm, standard uncertainty %.4f mm%s, cap half-angle %.0f deg, form (residual "
        "range) %s mm%s\n",
        position, k + 1, e.sphere_diameters_mm[k], e.sphere_diameter_std_mm[k], shared, e.sphere_cap_half_angles_deg[k],
        form.c_str(), e.type == ArtifactType::kBallBar ? " (not judged: the ball bar's figure is SD)" : "");
  }
}

// The certificate's values the figures are taken against, under the
// artifact file's keys.
nlohmann::json CertifiedJson(const Artifact& a) {
  switch (a.type) {
    case ArtifactType::kSphere:
      return {{"diameter_mm", a.sphere_diameter_mm},
              {"diameter_uncertainty_mm", a.sphere_diameter_uncertainty_mm},
              {"form_uncertainty_mm", a.sphere_form_uncertainty_mm}};
    case ArtifactType::kBallBar:
      return {{"sphere_diameter_mm", a.sphere_diameter_mm},
              {"sphere_diameter_uncertainty_mm", a.sphere_diameter_uncertainty_mm},
              {"center_distance_mm", a.center_distance_mm},
              {"center_distance_uncertainty_mm", a.center_distance_uncertainty_mm}};
    case ArtifactType::kPlate:
      return {{"length_mm", a.plate_length_mm},
              {"width_mm", a.plate_width_mm},
              {"flatness_uncertainty_mm", a.flatness_uncertainty_mm}};
  }
  return {};
}

// The MPE of each figure of the artifact's type and where it comes from: a
// file without mpe_mm (or without a figure's key in it) is judged against
// the default, said here and in the report (mpe_source).
void PrintMpes(const Artifact& artifact) {
  std::vector<std::pair<const char*, double>> mpes;
  switch (artifact.type) {
    case ArtifactType::kSphere:
      mpes = {{"P_F", artifact.mpe.probing_form_mm}, {"P_S", artifact.mpe.probing_size_mm}};
      break;
    case ArtifactType::kBallBar:
      mpes = {{"SD", artifact.mpe.sphere_spacing_mm}};
      break;
    case ArtifactType::kPlate:
      mpes = {{"F", artifact.mpe.flatness_mm}};
      break;
  }
  std::printf("MPE:");
  for (size_t k = 0; k < mpes.size(); ++k) {
    const bool given = artifact.mpe.Given(mpes[k].first);
    // As the certificate gives it: 0.34152 printed 0.3415.
    std::printf("%s %s %s mm (%s)", k ? "," : "", mpes[k].first, LimitText(mpes[k].second).c_str(),
                given ? "the artifact file's" : "default: the artifact file's mpe_mm gives none");
  }
  std::printf("\n");
}

std::string UncertaintyText(const Figure& f) {
  if (!f.standard_uncertainty_mm) return "-";
  return FixedText(*f.standard_uncertainty_mm, 4);
}

}  // namespace

int RunVerify(int argc, char** argv) {
  CLI::App app{kVerifyDescription, "stereorig verify"};
  app.footer(kVerifyFooter);
  std::string artifact_path, report_path;
  std::vector<std::string> clouds;
  VerifyOptions options;
  app.add_option("--artifact", artifact_path, "artifact file (YAML; docs/verify-and-check.md)")
      ->required()
      ->check(NonEmptyPath());
  app.add_option("--cloud", clouds, "point cloud (PLY, mm) of one position; repeat for several")
      ->required()
      ->check(NonEmptyPath());
  app.add_option("--report", report_path, "write the figures as JSON here")->check(NonEmptyPath());
  app.add_option("--min-points", options.min_points, "fewest points that must lie on the artifact (>= 10)")
      ->capture_default_str();
  app.add_option("--capture-band-mm", options.capture_band_mm,
                 "the artifact's points are those within this distance of the shape RANSAC\n"
                 "locates, mm; at least twice the figure's MPE is used (narrower, an error\n"
                 "beyond the MPE would be cut off). Widen it for a projector whose\n"
                 "grid-period-off error is deeper than ~3.5 mm")
      ->capture_default_str()
      ->check(PositiveValue());
  std::string rule_name = DecisionRuleName(options.decision_rule);
  app.add_option("--decision-rule", rule_name,
                 "simple (|value| <= MPE), guarded-acceptance (|value| + 2u <= MPE)\n"
                 "or guarded-rejection (fail only if |value| - 2u > MPE): ISO 14253-1, see above")
      ->capture_default_str()
      ->check(CLI::IsMember({DecisionRuleName(DecisionRule::kSimpleAcceptance),
                             DecisionRuleName(DecisionRule::kGuardedAcceptance),
                             DecisionRuleName(DecisionRule::kGuardedRejection)}));
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  options.decision_rule = *ParseDecisionRule(rule_name);
  // Named by the option, not as VerifyOptions::Check's min_points.
  if (options.min_points < 10)
    throw InputError("--min-points", "must be >= 10, got " + std::to_string(options.min_points));
  // A band wider than the largest sphere an artifact may hold takes in the
  // scene around it: 1e308 was taken where inf is refused, and 5000 (um for
  // 5 mm) took in a 5 m box.
  const std::string band_problem = ImplausibleMm(
      options.capture_band_mm, PlausibleMm{0.001, kSphereDiameter.max_mm, "capture band"}, "the option is in mm");
  if (!band_problem.empty()) throw InputError("--capture-band-mm", band_problem);
  OutputPaths outputs;  // the report's path checked before the clouds are read and judged
  outputs.Protect(artifact_path, "the artifact file (--artifact)");
  for (const std::string& cloud : clouds) outputs.Protect(cloud, "a cloud (--cloud)");
  if (!report_path.empty()) outputs.Claim(report_path, "the report (--report)");

  const Artifact artifact = ReadArtifactFile(artifact_path);
  std::vector<ArtifactEvaluation> positions;
  std::vector<int> filled_skipped;
  std::vector<std::string> read_notes;  // MeasuredPoints::note: a mesh without module
  for (const std::string& cloud : clouds) {
    const MeasuredPoints measured = ReadMeasuredPlyPoints(cloud);  // unreadable: bad input, nothing printed
    filled_skipped.push_back(measured.filled_skipped);
    read_notes.push_back(measured.note);
    try {
      positions.push_back(EvaluateArtifact(artifact, measured.points, options, cloud, measured.normals));
    } catch (const NotTheArtifactError& refused) {
      // The cloud read, but its points are not the artifact (too few on it,
      // none of the certified size): this position is not evaluated, and
      // the others are still shown; any other error is the run's.
      // Too few points where the cloud holds hole filling's: say that
      // those are skipped ("only 0 points" of a cloud of thousands read as
      // a broken file), as a sentence of its own after any hint the
      // refusal carries (metres).
      std::string problem = refused.problem();
      if (measured.filled_skipped > 0 && static_cast<int>(measured.points.size()) < options.min_points)
        problem += "; " + std::to_string(measured.filled_skipped) +
                   " more were added by hole filling (module 255), not measured: skipped";
      positions.push_back(NotEvaluated(artifact, options, static_cast<int>(measured.points.size()), problem));
    }
  }
  // A position left not judged (a figure the points or the certificate leave
  // undetermined) is still printed in full, marked so. A judged position that
  // fails fails the acceptance test whatever the others say: FAIL, exit 1,
  // the report written. Otherwise the run is not judged: exit 2 with the
  // reason on stderr and, as for bad input, no report written (an earlier
  // one at that path stays as it was: docs/formats.md).
  const VerifySummary summary = Summarise(positions);
  const bool all_judged = summary.not_judged_positions.empty();
  const bool judged_failure = std::any_of(positions.begin(), positions.end(),
                                          [](const ArtifactEvaluation& e) { return e.judged() && !e.pass(); });

  // The name is the file's text: escaped as every error line is, so a name
  // holding a line break cannot print a line of its own ("verdict: PASS").
  std::printf("artifact: %s (%s); capture band %.1f mm\n", PrintableText(artifact.name).c_str(),
              ArtifactTypeName(artifact.type), positions.front().capture_band_mm);
  // A band asked for below the floor is raised to it: said, or a band of
  // 1 mm read as used while 3 mm was.
  if (positions.front().capture_band_mm > options.capture_band_mm) {
    std::printf(
        "note: --capture-band-mm %g raised to %.1f mm, twice the MPE: a narrower band would cut off an error "
        "beyond the MPE before the figures see it\n",
        options.capture_band_mm, positions.front().capture_band_mm);
  }
  std::printf("decision rule: %s\n", DecisionRuleText(options.decision_rule));
  PrintMpes(artifact);
  // The same cloud given twice, or a byte-identical copy of it, is one
  // position, not two (the standard asks for positions that differ): said,
  // not refused (a test may repeat one).
  // A copy re-saved in another encoding (ASCII, big-endian) has other bytes
  // but the same fit: one measurement too (it counted as a new position).
  std::vector<RepeatedPosition> repeated = RepeatedPositions(clouds);
  std::vector<std::vector<double>> fitted_mm(positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    for (size_t k = 0; k < positions[i].sphere_centers_mm.size(); ++k) {
      const Eigen::Vector3d& c = positions[i].sphere_centers_mm[k];
      fitted_mm[i].insert(fitted_mm[i].end(), {c.x(), c.y(), c.z(), positions[i].sphere_diameters_mm[k]});
    }
  MarkSameFits(fitted_mm, &repeated);
  int distinct_positions = 0;
  for (size_t i = 0; i < clouds.size(); ++i) {
    if (repeated[i].earlier < 0) {
      ++distinct_positions;
      continue;
    }
    if (repeated[i].same_fit) {
      std::printf(
          "note: position %zu (%s) is the same measurement as position %d: its fitted centres and diameters agree "
          "with that one's within %g mm (the same cloud re-saved in another encoding?): the standard asks for "
          "positions that differ\n",
          i + 1, PrintableText(clouds[i]).c_str(), repeated[i].earlier + 1, kSameFitMm);
      continue;
    }
    std::printf("note: position %zu is %s position %d (%s): the standard asks for positions that differ\n", i + 1,
                repeated[i].same_file ? "the same cloud as" : "a byte-identical copy of the cloud of",
                repeated[i].earlier + 1, PrintableText(clouds[i]).c_str());
  }
  for (size_t i = 0; i < clouds.size(); ++i)
    if (!read_notes[i].empty())
      std::printf("note: position %zu (%s) is %s\n", i + 1, PrintableText(clouds[i]).c_str(), read_notes[i].c_str());
  // The point counts: cloud, then where each of its points went, each in
  // exactly one column (cloud = filled + off + edge + excluded + used).
  std::printf("%-8s %-6s %10s %8s %7s %4s %8s %7s %8s %7s %8s %8s %10s\n", "position", "figure", "value_mm", "u_mm",
              "mpe_mm", "pass", "cloud", "filled", "off", "edge", "excluded", "used", "mean|e|_mm");
  // Traceable: which certificate, its certified values, when and by what.
  nlohmann::json report = {{"artifact", artifact.name},
                           {"artifact_file", artifact_path},
                           {"certified", CertifiedJson(artifact)},
                           {"date_utc", NowUtcIso8601()},
                           {"tool", ToolVersion()},
                           {"type", ArtifactTypeName(artifact.type)},
                           {"uncertainty_coverage_factor", artifact.uncertainty_coverage_factor},
                           {"decision_rule", DecisionRuleName(options.decision_rule)},
                           {"decision_coverage_factor", kDecisionCoverageFactor}};
  for (size_t i = 0; i < positions.size(); ++i) {
    const ArtifactEvaluation& e = positions[i];
    nlohmann::json pj = {{"cloud", clouds[i]},
                         {"points_total", e.points_total + filled_skipped[i]},
                         {"points_filled_skipped", filled_skipped[i]},
                         {"points_off_artifact", e.points_off_artifact},
                         {"points_in_edge_margin", e.points_in_edge_margin},
                         {"points_on_artifact", e.points_on_artifact},
                         {"points_excluded", e.points_excluded},
                         {"points_used", e.points_used()},
                         {"capture_band_mm", e.capture_band_mm},
                         {"residual_mean_abs_mm", e.residual_mean_abs_mm},
                         {"residual_std_mm", e.residual_std_mm},
                         {"evaluated", e.evaluated},
                         {"judged", e.judged()},
                         {"pass", nullptr},
                         {"figures", nlohmann::json::array()}};
    if (!e.evaluated) {  // nothing was fitted: no counts on the artifact, no residuals
      for (const char* key : {"points_off_artifact", "points_in_edge_margin", "points_on_artifact", "points_excluded",
                              "points_used", "residual_mean_abs_mm", "residual_std_mm"})
        pj[key] = nullptr;
      std::printf("%-8zu %-6s %10s %8s %7s %4s %8d %7d %8s %7s %8s %8s %10s\n", i + 1, "-", "-", "-", "-", "-",
                  e.points_total + filled_skipped[i], filled_skipped[i], "-", "-", "-", "-", "-");
    }
    if (e.judged()) {
      pj["pass"] = e.pass();
    } else {
      pj["not_judged_reason"] = e.not_judged_reason;
    }
    // The edge margin is the plate's alone: '-' for the others.
    const std::string edge = e.type == ArtifactType::kPlate ? std::to_string(e.points_in_edge_margin) : "-";
    for (const Figure& f : e.figures) {
      // The value with the digits that order it against the MPE as the verdict does.
      std::printf("%-8zu %-6s %10s %8s %7s %4s %8d %7d %8d %7s %8d %8d %10s\n", i + 1, f.name.c_str(),
                  ValueBesideLimitText(f.value_mm, f.mpe_mm).c_str(), UncertaintyText(f).c_str(),
                  LimitText(f.mpe_mm).c_str(),
                  !e.judged() || !f.judged ? "-"
                  : f.pass                 ? "yes"
                                           : "NO",
                  e.points_total + filled_skipped[i], filled_skipped[i], e.points_off_artifact, edge.c_str(),
                  e.points_excluded, e.points_used(), FixedText(e.residual_mean_abs_mm, 4).c_str());
      pj["figures"].push_back(FigureJson(f, e.judged(), artifact));
    }
    for (const Figure& f : e.figures) {
      PrintUncertainty(i + 1, f, artifact.uncertainty_coverage_factor);
      if (!f.standard_uncertainty_mm && options.decision_rule != DecisionRule::kSimpleAcceptance) {
        std::printf("%-8zu %s: no u (%s): judged with 2u = 0, as simple acceptance does\n", i + 1, f.name.c_str(),
                    f.name == "P_F" ? "the artifact file gives no form_uncertainty_mm" : "an exact certificate");
      }
    }
    PrintSpheres(i + 1, e);
    if (!e.sphere_centers_mm.empty()) pj["spheres"] = SpheresJson(e);
    if (e.type == ArtifactType::kPlate && e.evaluated) {
      std::printf(
          "%-8zu plate face: outline %.1f x %.1f mm (of its dense part; %d captured points not in the dense part, "
          "%d of them outside the outline, counted in off)\n",
          i + 1, e.plate_outline_length_mm, e.plate_outline_width_mm, e.plate_points_off_outline,
          e.plate_points_outside_rectangle);
      pj["plate_outline_mm"] = {e.plate_outline_length_mm, e.plate_outline_width_mm};
      // Its meaning since it came: the captured points not in the dense part.
      pj["plate_points_off_outline"] = e.plate_points_off_outline;
      pj["plate_points_outside_rectangle"] = e.plate_points_outside_rectangle;
      pj["plate_points_far_face"] = e.plate_points_far_face;
    }
    for (const std::string& note : e.notes) std::printf("%-8zu note: %s\n", i + 1, note.c_str());
    if (!e.notes.empty()) pj["notes"] = e.notes;
    if (!e.judged()) std::printf("%-8zu NOT JUDGED: %s\n", i + 1, e.not_judged_reason.c_str());
    report["positions"].push_back(pj);
  }
  std::printf(
      "u_mm = the figure's standard uncertainty (k = 1): the fit's (its covariance, with the noise neighbouring points "
      "share) and the certificate's (U / k) "
      "in quadrature; points: cloud = all vertices = filled + off + edge + excluded + used; "
      "filled = added by hole filling (module 255), skipped; off = not the artifact's (outside the capture band%s); "
      "edge = in the plate's %.0f mm edge margin, not evaluated (- for other artifacts); excluded = the "
      "largest residuals (<= 0.3%% of those on the artifact); used = in the figures; mean|e|_mm = the mean |residual| "
      "of the points used to "
      "the fitted shape(s); pass: under the decision rule, - = not judged (the line NOT JUDGED says why)%s\n",
      artifact.type == ArtifactType::kBallBar ? ", or in the shaft's cone"
      : artifact.type == ArtifactType::kPlate ? ", or outside the face's outline, or on its far face"
                                              : "",
      options.plate_edge_margin_mm,
      artifact.type == ArtifactType::kPlate
          ? ""
          : "; cap half-angle = the cone about the points' mean direction from the sphere's centre that holds 99% of "
            "them: 90 deg a hemisphere, over 90 more than one (near 180 a sphere seen from both sides)");
  const size_t judged = positions.size() - summary.not_judged_positions.size();
  if (all_judged) {
    std::printf("summary over %zu position(s):", positions.size());
  } else if (judged == 0) {
    std::printf("summary: no position judged");
  } else {
    std::printf("summary over the %zu judged of %zu position(s):", judged, positions.size());
  }
  report["summary"]["worst"] = nlohmann::json::array();
  for (size_t k = 0; k < summary.worst.size(); ++k) {
    const Figure& f = summary.worst[k];
    const int at = summary.worst_positions[k] + 1;  // numbered as in the table
    const std::string value = ValueBesideLimitText(f.value_mm, f.mpe_mm), mpe = LimitText(f.mpe_mm);
    if (options.decision_rule != DecisionRule::kSimpleAcceptance && f.standard_uncertainty_mm) {
      std::printf("  %s %s mm (2u %s mm, MPE %s mm) %s", f.name.c_str(), value.c_str(),
                  FixedText(f.ExpandedUncertaintyMm(), 4).c_str(), mpe.c_str(), f.pass ? "pass" : "FAIL");
    } else {
      std::printf("  %s %s mm (MPE %s mm) %s", f.name.c_str(), value.c_str(), mpe.c_str(), f.pass ? "pass" : "FAIL");
    }
    if (positions.size() > 1) std::printf(" at position %d", at);
    nlohmann::json worst = FigureJson(f, true, artifact);
    worst["position"] = at;
    report["summary"]["worst"].push_back(worst);
  }
  const char* verdict = judged_failure ? "FAIL" : !all_judged ? "NOT JUDGED" : "PASS";
  std::printf("\nverdict: %s", verdict);
  // What a PASS says under a guarded rule, with the stated u (a floor: the
  // fit's covariance and the certificate, docs/verify-and-check.md).
  if (all_judged && !judged_failure && options.decision_rule == DecisionRule::kGuardedAcceptance) {
    std::printf(" (guarded acceptance: every figure within its MPE by 2u)");
  } else if (all_judged && !judged_failure && options.decision_rule == DecisionRule::kGuardedRejection) {
    std::printf(" (guarded rejection: no figure beyond its MPE by 2u; a figure may still exceed it)");
  }
  report["summary"]["verdict"] = verdict;
  report["summary"]["pass"] = summary.pass;
  report["summary"]["positions_not_judged"] = nlohmann::json::array();
  for (int k : summary.not_judged_positions) {
    report["summary"]["positions_not_judged"].push_back(k + 1);  // numbered as in the table
    std::printf("%s%d", k == summary.not_judged_positions.front() ? " (position " : ", ", k + 1);
  }
  // Why the positions not judged are not, each reason once in this order.
  bool not_evaluated = false, beyond_band = false, undetermined = false;
  for (int k : summary.not_judged_positions) {
    const ArtifactEvaluation& e = positions[k];
    (!e.evaluated ? not_evaluated : e.beyond_band_not_judged ? beyond_band : undetermined) = true;
  }
  std::string why;
  for (const auto& [given, text] : {std::pair{undetermined, "a figure left undetermined"},
                                    std::pair{beyond_band, "a part measured beyond the capture band"},
                                    std::pair{not_evaluated, "a cloud not evaluated"}})
    if (given) why += (why.empty() ? "" : " or ") + std::string(text);
  if (all_judged) {
    std::printf("\n");
  } else if (judged_failure) {
    std::printf(" not judged: %s)\n", why.c_str());
  } else {
    std::printf(": %s; exit 2, no report written)\n", why.c_str());
  }
  // The verdict stands, but over fewer positions than the procedure asks
  // for it is not its acceptance test: said under it, and in the report.
  report["summary"]["positions_given"] = clouds.size();
  report["summary"]["positions_distinct"] = distinct_positions;
  report["summary"]["positions_asked"] = kPositionsAsked;
  if (distinct_positions < kPositionsAsked) {
    std::printf(
        "note: %d distinct position(s) measured; the procedure asks for %d or more spread through the volume "
        "(docs/verify-and-check.md): this verdict covers the positions measured only\n",
        distinct_positions, kPositionsAsked);
  }
  // The table is the verdict: one that could not be written (a full disk,
  // /dev/full) is an error, not exit 0, and leaves no report behind.
  RequireStdoutWritten();
  if (!report_path.empty() && (all_judged || judged_failure))
    WriteFileAtomically(report_path, JsonReportText(report) + "\n");
  if (!all_judged && !judged_failure) {
    // One line on stderr, as for bad input: the first position's reason.
    const int first = summary.not_judged_positions.front();
    std::string problem = positions[first].not_judged_reason;
    if (summary.not_judged_positions.size() > 1) {
      char more[96];
      std::snprintf(more, sizeof more, " (and %zu more position(s) not judged: the table says why)",
                    summary.not_judged_positions.size() - 1);
      problem += more;
    }
    throw InputError(clouds[first], problem);
  }
  return summary.pass ? kExitOk : kExitCheckFailed;
}

}  // namespace stereorig
