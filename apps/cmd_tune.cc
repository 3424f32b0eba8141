// `stereorig tune`: the laser grid's period measured in a capture, and the
// runtime options tied to it set from it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "apps/tuned_options.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/number_text.h"
#include "calib/core/rig_file.h"
#include "reconstruct/grid_line_width.h"
#include "reconstruct/grid_period.h"
#include "reconstruct/grid_period_options.h"
#include "reconstruct/lit_mask.h"
#include "reconstruct/metrology/plane_fit.h"
#include "reconstruct/runtime.h"

namespace stereorig {
namespace {

// A module's period varying by more than this share over its image (half
// the blocks' interquartile range) says the surface was not a plane facing
// it: the period then mixes foreshortenings, and is not the grid's own.
constexpr double kMaxRelativeSpread = 0.05;
// Modules whose periods differ by more than this share: one set of options
// serves them all, so it takes their median, and says so.
constexpr double kMaxRelativeModuleDifference = 0.05;

// The rectified left image of each module and its grid-lit pixels within
// the volume's ROI, as the runtime finds them (its rectification and lit
// mask), measured.
std::optional<GridPeriodMeasurement> MeasureModule(const Runtime& runtime, const ModulePlan& plan,
                                                   const std::vector<cv::Mat>& images) {
  const cv::Mat left = runtime.Rectify(plan, images).first;
  cv::Mat lit = cv::Mat::zeros(left.size(), CV_8UC1);
  // Not the step to the view's zero fill (lit_mask.h): no grid there.
  cv::bitwise_and(LitMask(left(plan.roi), runtime.options().lit_contrast_dn), plan.lit_window_on_data(plan.roi),
                  lit(plan.roi));
  return MeasureGridPeriodPx(left, lit);
}

// A module's points lying farther than this RMS off their plane say the
// capture is not a flat plate: the period, stretched by the foreshortening
// where the surface turns, is not the grid's own. The blocks' spread does
// not show it: each block's period is summed along whole rows, so a surface
// curved along them (or turned as a whole) reads alike in every block. On
// the demo scenes (each module): plate 0.07 mm; sphere 2.9, ball bar 3.4,
// cup 3.4-3.6, tuber 4.1 mm, whose P read 8.21-8.46 px against the plate's
// 8.07 while their spreads stayed 0.03-0.29 px. 0.5 mm is 7x the plate's
// noise and a sixth of the nearest curved scene.
constexpr double kMaxPlaneRmsMm = 0.5;
// A module's points, fitted with a plane (FitPlaneLeastSquares): the RMS of
// their distances to it, mm. Nothing with fewer than kMinPlanePoints points.
constexpr int kMinPlanePoints = 1000;
std::optional<double> PlaneRmsMm(const PointCloud& cloud, int module) {
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (cloud.module[i] == module) points.push_back(cloud.xyz_mm[i].cast<double>());
  if (points.size() < kMinPlanePoints) return std::nullopt;
  std::vector<int> all(points.size());
  std::iota(all.begin(), all.end(), 0);
  const PlaneFit fit = FitPlaneLeastSquares(points, all);
  if (!fit.ok) return std::nullopt;
  return fit.rms_mm;
}

// The share of a module's grid-lit pixels that the grid-line test refused
// (no_grid_line, as `reconstruct --report`'s lit_pixels_by_status counts
// them), in %; nullopt for a module with no lit pixel.
std::optional<double> NoGridLinePercent(const Reconstruction& reconstruction, int module) {
  for (const ModuleReport& m : reconstruction.modules)
    if (m.module == module && m.lit_pixels > 0)
      return 100.0 * m.lit_by_status[size_t(PixelStatus::kNoGridLine)] / m.lit_pixels;
  return std::nullopt;
}

}  // namespace

int RunTune(int argc, char** argv) {
  CLI::App app{
      "Measures the laser grid's period P in a capture (the distance between neighbouring near-vertical lines "
      "along the rows of each module's rectified left image) and sets the runtime options tied to it, P taken to "
      "the nearest pixel: match.grid_half_period_px (P / 2, at most 4: the distinctness test's shift; longer, its "
      "probes pass mismatches at rims), match.line_index_max_shift_px (1.5 P), "
      "match.line_index_window_half_height_px (at least (P - 1) / 2), match.line_index_footprint_gap_px (P, at "
      "most 16) and match.grid_line_radius_px (P / 2 rounded up, + 1), but not wider than --options has it: a wider "
      "window also keeps matches on objects' outlines beyond the grid's envelope, and can raise the std, so a wider "
      "value is printed as a suggestion to verify, with the share of each module's grid-lit pixels the grid-line "
      "test refused (no_grid_line; on the plate it did not tell where widening helps). The defaults are these "
      "rules at the default grid's 8 px, so on a rig like the default nothing changes. Use it when commissioning "
      "a rig with another projector, lens or working distance (docs/reconstruct.md, 'Another projector'). A P "
      "within 0.1 px of a half pixel is warned of: another capture may round it the other way.\n"
      "Capture a flat matte plate facing the modules, lasers on, filling the measurement volume's middle: on a "
      "curved or turned surface the period is stretched by the foreshortening. Per module it reconstructs the "
      "capture and prints how far its points lie off a plane (RMS), and warns above 0.5 mm: not a flat plate; "
      "a plate turned away from the module is not detected (its period is stretched alike everywhere). The other keys "
      "of --options are kept; --out writes them with the new ones (YAML comments "
      "of --options are not carried over).\n\n"
      "Exit codes: 0 ok (its warnings too); 2 bad usage or input (a capture that shows no grid period included).\n\n"
      "Example:\n  stereorig tune --rig rig.yaml --capture plate --options line.yaml --out line_tuned.yaml\n"
      "  stereorig reconstruct --rig rig.yaml --capture part1 --options line_tuned.yaml --out part1.ply",
      "stereorig tune"};
  std::string rig_path, capture_dir, options_path, out_path;
  app.add_option("--rig", rig_path, "rig file (from stereorig calibrate)")->required();
  app.add_option("--capture", capture_dir, "capture folder (camK.png per camera) of a flat plate, lasers on")
      ->required();
  app.add_option("--options", options_path, "runtime options YAML to start from (default: the built-in defaults)");
  app.add_option("--out", out_path, "write the tuned runtime options here (.yaml); without it, only print them")
      ->check(NonEmptyPath());
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  const Rig rig = ReadRigFile(rig_path);
  OutputPaths outputs;
  ProtectCaptureInputs(rig_path, options_path, capture_dir, rig, &outputs);
  if (!out_path.empty()) {
    outputs.Claim(out_path, "the tuned options (--out)");
    CheckOptionsPath(out_path);
  }
  // Read once: --options may be a pipe, and --out keeps its keys.
  const std::string options_text = options_path.empty() ? "" : ReadInputText(options_path);
  RuntimeOptions options = options_path.empty() ? RuntimeOptions{} : ParseRuntimeOptions(options_text, options_path);
  const std::vector<cv::Mat> images = LoadCapture(capture_dir, rig);
  const Runtime runtime(rig, options);

  const Reconstruction reconstruction = runtime.Process(images, false);
  std::vector<double> periods;
  std::string measured;      // "module 0 8.07 px (spread 0.04 px, turned 2.53 deg), ...": the file's header
  std::string unmeasured;    // "module 1, module 2": those with no period, warned of and named in the header
  std::string no_grid_line;  // "module 0 1.99 %, ...": the grid-lit pixels the grid-line test refused
  double max_no_grid_line_percent = 0;
  for (const ModulePlan& plan : runtime.plans()) {
    const auto m = MeasureModule(runtime, plan, images);
    if (!m) {
      std::printf("module %d: no grid period found in its lit region (too few lit rows, or no lines)\n", plan.module);
      unmeasured += (unmeasured.empty() ? "module " : ", module ") + std::to_string(plan.module);
      continue;
    }
    std::printf("module %d: grid period %.2f px along the rows, spread %.2f px over %d blocks of %d rows\n",
                plan.module, m->period_px, m->spread_px, m->blocks, GridPeriodOptions{}.block_rows);
    if (m->spread_px > kMaxRelativeSpread * m->period_px)
      std::fprintf(stderr,
                   "tune: warning: module %d's period varies by more than %.0f %% over its image: a curved or turned "
                   "surface; measure on a flat plate facing the module\n",
                   plan.module, 100 * kMaxRelativeSpread);
    if (const std::optional<double> rms_mm = PlaneRmsMm(reconstruction.cloud, plan.module)) {
      std::printf("  its points lie %.2f mm RMS off a plane\n", *rms_mm);
      if (*rms_mm > kMaxPlaneRmsMm)
        std::fprintf(stderr,
                     "tune: warning: module %d's points in %s lie %.2f mm RMS off a plane (more than %.1f mm): not a "
                     "flat plate, and the period is stretched where the surface turns; measure on a flat plate "
                     "facing the module\n",
                     plan.module, capture_dir.c_str(), *rms_mm, kMaxPlaneRmsMm);
    } else {
      // Said on stderr too, as a surface found curved is: its period counts
      // as much, and only this line said the plate was never checked (its
      // right camera dark, or its matches failing, on a plate or a cup).
      std::printf("  its flatness was not read (fewer than %d points)\n", kMinPlanePoints);
      std::fprintf(stderr,
                   "tune: warning: module %d's flatness was not read in %s (fewer than %d points: its right image "
                   "dark, or few matches): its period is from a surface not known to be a flat plate; check the "
                   "capture\n",
                   plan.module, capture_dir.c_str(), kMinPlanePoints);
    }
    if (const std::optional<double> percent = NoGridLinePercent(reconstruction, plan.module)) {
      std::printf("  the grid-line test refused %.2f %% of its grid-lit pixels (no_grid_line)\n", *percent);
      char share[48];
      std::snprintf(share, sizeof share, "%smodule %d %.2f %%", no_grid_line.empty() ? "" : ", ", plan.module,
                    *percent);
      no_grid_line += share;
      max_no_grid_line_percent = std::max(max_no_grid_line_percent, *percent);
    }
    if (std::isnan(m->shift_per_row_px)) {
      std::printf(
          "  its turn against the rows was not read: check the line index's vernier by hand "
          "(docs/reconstruct.md, \"Another projector\")\n");
    } else {
      const double offset_px = RowOffsetPerPeriodPx(*m);
      std::printf(
          "  the grid is turned %.2f deg against the rows: the line index's vernier reads %.2f px per period "
          "(its thresholds need %.2f-%.2f)\n",
          GridTurnDeg(*m), offset_px, kMinRowOffsetPerPeriodPx, kMaxRowOffsetPerPeriodPx);
      if (offset_px < kMinRowOffsetPerPeriodPx || offset_px > kMaxRowOffsetPerPeriodPx)
        std::fprintf(
            stderr,
            "tune: warning: at this turn module %d's line index cannot tell a line from its neighbour reliably (at "
            "strong speckle a component a line off may be kept, or the right one dropped): turn the projector "
            "about its axis so that P tan(turn) lies in %.2f-%.2f px (docs/reconstruct.md, \"Another "
            "projector\")\n",
            plan.module, kMinRowOffsetPerPeriodPx, kMaxRowOffsetPerPeriodPx);
    }
    if (std::isnan(m->line_sigma_over_period)) {
      std::printf(
          "  its lines' width was not read (a period under %.0f px, saturated lines, or lines so wide that "
          "their profile is a sinusoid)\n",
          kMinLineWidthPeriodPx);
    } else {
      std::printf(
          "  its lines are %.2f px wide (sigma along the rows): %.3f of the period (the runtime is tuned "
          "for up to %.2f)\n",
          m->line_sigma_over_period * m->period_px, m->line_sigma_over_period, kMaxLineSigmaOverPeriod);
      if (m->line_sigma_over_period > kMaxLineSigmaOverPeriod)
        std::fprintf(stderr,
                     "tune: warning: module %d's lines are wide for their period (sigma %.3f of it): the grid fades "
                     "towards a sinusoid, which looks the same a period off, and the matcher loses fill or keeps "
                     "patches a line off. Focus the projector's lines, or use a longer period "
                     "(docs/reconstruct.md, \"Another projector\")\n",
                     plan.module, m->line_sigma_over_period);
    }
    periods.push_back(m->period_px);
    char text[192];
    const std::string turn =
        std::isnan(m->shift_per_row_px) ? "turn not read" : "turned " + NumberText(GridTurnDeg(*m), 3) + " deg";
    const std::string width = std::isnan(m->line_sigma_over_period)
                                  ? "line width not read"
                                  : "lines sigma " + NumberText(m->line_sigma_over_period, 3) + " P";
    std::snprintf(text, sizeof text, "module %d %.2f px (spread %.2f px, %s, %s)", plan.module, m->period_px,
                  m->spread_px, turn.c_str(), width.c_str());
    measured += (measured.empty() ? "" : ", ") + std::string(text);
  }
  if (periods.empty())
    throw InputError(capture_dir,
                     "no module's left image shows a laser grid's period (" + NumberText(kMinGridPeriodPx) + "-" +
                         NumberText(kMaxGridPeriodPx) +
                         " px along the rows): are the lasers on, and the plate inside the measurement volume? (a "
                         "passive capture has no grid)");
  // The keys then come from the other modules alone: said on stderr and in
  // the file, not only in a stdout line that a script drops.
  if (!unmeasured.empty())
    std::fprintf(stderr,
                 "tune: warning: no grid period was found for %s in %s (too few lit rows, or no lines: its lasers "
                 "off, or the plate outside its view): the keys are set from the other modules only; capture the "
                 "plate with every module's lasers on\n",
                 unmeasured.c_str(), capture_dir.c_str());
  std::vector<double> sorted = periods;
  std::sort(sorted.begin(), sorted.end());
  const double period_px = 0.5 * (sorted[(sorted.size() - 1) / 2] + sorted[sorted.size() / 2]);
  if (sorted.back() - sorted.front() > kMaxRelativeModuleDifference * period_px)
    std::fprintf(
        stderr,
        "tune: warning: the modules' periods differ by more than %.0f %% (%.2f to %.2f px): one set of options "
        "serves them all, so it takes their median\n",
        100 * kMaxRelativeModuleDifference, sorted.front(), sorted.back());

  if (!(period_px >= kMinGridPeriodPx && period_px <= kMaxGridPeriodPx))
    throw InputError(capture_dir, "the grid's period, " + NumberText(period_px) +
                                      " px (the modules' median), is outside the " + NumberText(kMinGridPeriodPx) +
                                      "-" + NumberText(kMaxGridPeriodPx) + " px the runtime's keys can serve");
  const std::vector<GridPeriodKey> keys = SetGridPeriodKeys(period_px, &options.match);
  try {  // a key of --options may not fit the new ones (grid_line_min_ridge_px and a smaller radius)
    options.Check();
  } catch (const InputError& e) {
    throw InputError(options_path.empty() ? capture_dir : options_path,
                     "with the keys tune sets, " + std::string(e.what()));
  }
  std::printf("P = %.2f px, taken as %ld px:\n", period_px, std::lround(period_px));
  if (const int other_px = OtherRoundedPeriodPx(period_px))
    std::fprintf(
        stderr,
        "tune: warning: P lies within %.1f px of the half pixel, so another capture of this rig may read it as %d px "
        "and set other keys: measure the plate in a second position, and keep the set that verifies better\n",
        kRoundingMarginPx, other_px);
  std::string not_applied;  // the file header's note on the rules not applied
  for (const GridPeriodKey& k : keys) {
    if (k.rule_not_applied == 0) {
      std::printf("  match.%-34s %g%s\n", k.key.c_str(), k.value,
                  k.value == k.before ? "  (unchanged)" : ("  (was " + NumberText(k.before) + ")").c_str());
      continue;
    }
    std::printf("  match.%-34s %g  (kept: the rule gives %g, not applied)\n", k.key.c_str(), k.value,
                k.rule_not_applied);
    not_applied += "\nmatch." + k.key + " was kept at " + NumberText(k.value) + ": the rule gives " +
                   NumberText(k.rule_not_applied) + ", not applied (docs/reconstruct.md, \"Another projector\").";
  }
  for (const GridPeriodKey& k : keys)
    if (k.rule_not_applied != 0 && k.key == "grid_line_radius_px")
      // docs/reconstruct.md's condition, with the share it names (printed
      // per module above): read on the plate, it did not tell the rigs
      // where widening helped from those where it hurt.
      std::printf(
          "grid_line_radius_px: the rule's %g px (P / 2 rounded up, + 1) widens the grid-line test's window, which "
          "also keeps matches on objects' outlines beyond the grid's envelope and can raise the std; the plate's "
          "no_grid_line share (here at most %.2f %% of a module's grid-lit pixels) does not tell whether it helps "
          "(docs/reconstruct.md, \"Another projector\"), so the radius is kept. To try it, set "
          "match.grid_line_radius_px: %g and verify on the sphere and the ball bar in several positions\n",
          k.rule_not_applied, max_no_grid_line_percent, k.rule_not_applied);
  const bool any_changed =
      std::any_of(keys.begin(), keys.end(), [](const GridPeriodKey& k) { return k.value != k.before; });
  if (!any_changed && not_applied.empty())
    std::printf("the keys already fit this grid\n");
  else if (any_changed)
    std::printf(
        "check the accuracy with the new keys: stereorig verify on the sphere and the ball bar, several "
        "positions (docs/reconstruct.md, \"Another projector\")\n");
  if (out_path.empty()) {
    std::printf("no --out: nothing written\n");
    return kExitOk;
  }
  const std::string header =
      "Runtime options from `stereorig tune --capture " + capture_dir + "` with the rig " + rig_path +
      ".\nThe laser grid's period along the rectified rows: " + measured +
      ".\nThe match keys tied to it were set from P = " + NumberText(period_px) +
      " px (docs/reconstruct.md, \"Another projector\")." + not_applied +
      (no_grid_line.empty()
           ? ""
           : "\nThe grid-lit pixels the grid-line test refused (no_grid_line): " + no_grid_line + ".") +
      (unmeasured.empty() ? ""
                          : "\nNo grid period was found for " + unmeasured +
                                " (its lasers off, or the plate outside its view): these keys "
                                "are the other modules' only.");
  const std::string text = TunedOptionsYaml(options_text, keys, header);
  ParseRuntimeOptions(text, out_path).Check();  // what a later --options will read: the same keys, valid
  WriteFileAtomically(out_path, text);
  std::printf("wrote %s\n", out_path.c_str());
  return kExitOk;
}

}  // namespace stereorig
