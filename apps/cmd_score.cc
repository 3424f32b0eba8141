// `stereorig score`: the runtime judged on a simulator dataset against its
// truth, as issue 5 judges it: accuracy after one rigid alignment to the
// dense truth surface, the fill of the object pixels both cameras of a
// module see and a grid lights, and the active/passive valid-point ratio.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/module_summary.h"
#include "apps/output_paths.h"
#include "apps/reconstruct_json.h"
#include "apps/truth_rig_warning.h"
#include "apps/volume_warning.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "calib/json_text.h"
#include "reconstruct/fill_diagnosis.h"
#include "reconstruct/runtime.h"
#include "reconstruct/scene_score.h"

namespace stereorig {
namespace {

nlohmann::json FillJson(const FillFigures& f) {
  nlohmann::json j = {
      {"target_px", f.target_px}, {"filled_px", f.filled_px}, {"fill", f.fill()}, {"points_off_target", f.other_px}};
  for (size_t k = 0; k < f.target_status.size(); ++k)
    if (f.target_status[k] && k != size_t(PixelStatus::kPoint))
      j["target_px_lost_by"][PixelStatusName(PixelStatus(k))] = f.target_status[k];
  return j;
}

// "12695 points, |e| mean 0.52 p95 1.40 max 2.31 mm, 61.0% within 0.5 mm".
std::string FilledLine(const ErrorFigures& f) {
  if (f.points <= 0) return "no point";
  char buf[160];
  std::snprintf(buf, sizeof buf, "%6d points, |e| mean %.3f p95 %.3f max %.3f mm, %5.1f%% within 0.5 mm", f.points,
                f.mean_abs_mm, f.p95_abs_mm, f.max_abs_mm, 100 * f.within_0_5_mm);
  return buf;
}

}  // namespace

int RunScore(int argc, char** argv) {
  CLI::App app{
      "Judges the reconstruction runtime on a simulator dataset against its ground truth: for each scene, "
      "reconstructs the active capture (and the passive one), aligns the merged cloud to the dense truth surface "
      "by one rigid motion (reported), and reports mean |error| and std per module and merged; the fill rate of "
      "each module over the object pixels that both its cameras see and a laser grid lights (from the truth's "
      "depth, id and lit maps); and the active/passive valid-point ratio (passive: the same options without the "
      "lit-region crop, the grid-period distinctness test, the grid-line test and the line index). With a shape_model "
      "in --options, the hole-filling points too: their distance to the truth surface (mean, p95, max, share within "
      "0.5 mm), "
      "overall and by their distance to the nearest measured point (0-5, 5-15, >= 15 mm). Judge with the rig file "
      "from `stereorig calibrate`, as the line will run: without --rig the dataset's truth rig is used (and said "
      "so), which leaves out the calibration's own error.\n\n"
      "Exit codes: 0 ok (score judges nothing: no figure fails); 2 bad usage or input.\n\n"
      "Example:\n  stereorig score --dataset demo/dataset --rig demo/rig.yaml --report score.json",
      "stereorig score"};
  std::string dataset, rig_path, options_path, report_path, diagnose_dir, scenes_arg = "cup,sphere,ballbar,plate,tuber";
  bool no_passive = false;
  app.add_option("--dataset", dataset, "simulator dataset folder (scenes/, truth/)")->required();
  app.add_option("--rig", rig_path, "rig file to reconstruct with (default: DATASET/truth/rig.yaml)");
  app.add_option("--scenes", scenes_arg,
                 "comma-separated scenes; each one named must be in the dataset (scenes/<name>/active), or score "
                 "exits 2 before any scoring; by default, those of the five the dataset holds "
                 "(cup,sphere,ballbar,plate,tuber)");
  app.add_option("--options", options_path, "runtime options YAML");
  app.add_option("--report", report_path,
                 "write everything as JSON here (its keys and units: docs/reconstruct.md, \"Score report JSON\")")
      ->check(NonEmptyPath());
  app.add_option("--diagnose", diagnose_dir,
                 "write where and why fill is lost here: per scene and module, PNGs of the pixel status, the lost "
                 "target pixels (green: the truth disparity passes the tests, red: not) and |disparity - truth| "
                 "(reconstruct/fill_diagnosis.h), and a table on stdout")
      ->check(NonEmptyPath());
  app.add_flag("--no-passive", no_passive, "skip the passive captures (no active/passive ratio)");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  namespace fs = std::filesystem;
  const bool rig_given = !rig_path.empty();
  if (!rig_given) rig_path = (fs::path(dataset) / "truth" / "rig.yaml").string();
  // Before any work: an unusable --diagnose folder is bad input, not a crash
  // at the end; but it is created only after every input check below.
  // (FolderToCreate, calib/core/folder_to_create.h: removed again, while
  // empty, if the run fails after it is made.)
  FolderToCreate diagnose;
  if (!diagnose_dir.empty()) diagnose = OutputPaths().ClaimFolder(diagnose_dir, "the diagnosis images (--diagnose)");
  // Before anything is read: the report, not over the rig, the options or
  // any file of the dataset the scorer reads (its folder may be one
  // --diagnose will create); once the rig says how many modules, the
  // diagnosis images too, against the same claims.
  if (!report_path.empty() && diagnose.WillCreate(fs::absolute(report_path)))
    throw InputError(report_path, "is a folder --diagnose creates, not a file for the report (--report)");
  OutputPaths outputs = ClaimRuntimeReport(
      {.path = report_path,
       .rig_path = rig_path,
       .rig_what = rig_given ? "the rig file (--rig)" : "the dataset's truth rig file (read without --rig)",
       .options_path = options_path,
       .check_folder = report_path.empty() || !diagnose.WillCreate(fs::absolute(report_path).parent_path()),
       .more_inputs = DatasetInputs(dataset)});
  CheckDatasetFolder(dataset, true);  // named as what it is, not as a missing truth/rig.yaml
  const Rig rig = ReadRigFile(rig_path);
  // The truth's fill target and depth are the truth rig's module m's, taken
  // for the cloud's module m: a --rig pairing other cameras in a module (its
  // layout another's) was scored against the wrong truth, exit 0.
  // Read once: the diagnosis takes each module's left camera from it too.
  const std::string truth_rig_path = (fs::path(dataset) / "truth" / "rig.yaml").string();
  const Rig truth_rig = rig_given ? ReadRigFile(truth_rig_path) : rig;
  if (rig_given) RequireTruthRigLayout(rig, rig_path, truth_rig, truth_rig_path, "score");
  // Every scene named is in the dataset, before any is scored: a scene
  // misnamed after others in --scenes used to be found only once they were
  // scored, their diagnosis images left in a new --diagnose folder. The
  // default list takes the scenes of it the dataset holds, as bench's does
  // (it used to require all five, and refused a smaller dataset as if the
  // user had named them).
  const std::vector<std::string> scenes = ScenesToRun(dataset, SplitSceneList(scenes_arg), app.count("--scenes") > 0);
  if (!diagnose_dir.empty()) {
    for (const std::string& name : scenes)
      for (int m = 0; m < rig.num_modules(); ++m)
        for (const std::string& path : FillDiagnosisImagePaths(FillDiagnosisPrefix(diagnose_dir, name, m)))
          outputs.Claim(path, "a diagnosis image (--diagnose)", false);
  }
  // Each scene's capture files and truth, before any is scored.
  for (const std::string& name : scenes) {
    const fs::path scene_dir = fs::path(dataset) / "scenes" / name;
    CheckCaptureFiles((scene_dir / "active").string(), rig);
    if (!no_passive && fs::is_directory(scene_dir / "passive"))
      CheckCaptureFiles((scene_dir / "passive").string(), rig);
    const fs::path surface = fs::path(dataset) / "truth" / "scenes" / name / "surface.ply";
    if (!fs::is_regular_file(surface)) throw InputError(surface.string(), "no such file (the scene's truth)");
  }
  const RuntimeOptions options = options_path.empty() ? RuntimeOptions{} : ReadRuntimeOptions(options_path);
  const Runtime runtime(rig, options), passive_runtime(rig, PassiveOptions(options));
  diagnose.Create();
  // The diagnosis images and the report, all or none (calib/core/atomic_file.h):
  // a later scene's bad input (a damaged truth map, a passive capture image)
  // used to leave the earlier scenes' images written, in a new --diagnose
  // folder or over an earlier run's among its others. Declared after
  // `diagnose`: their temporary files go before the folder made for them.
  AtomicOutputSet written;
  std::vector<std::string> earlier_images;  // of modules that make none: removed once the run's are written
  nlohmann::json report = {{"dataset", dataset}, {"rig", rig_path}};
  {
    std::ifstream spec(fs::path(dataset) / "spec.yaml");
    std::stringstream text;
    text << spec.rdbuf();
    report["spec_yaml"] = text.str();
  }
  for (const std::string& name : scenes) {
    const fs::path scene_dir = fs::path(dataset) / "scenes" / name;
    const SceneTruth truth = ReadSceneTruth(dataset, name);
    // The truth frame is the truth rig's module 0, the volume the rig
    // file's: close enough (a calibrated rig differs by a fraction of a
    // mm) to tell a volume that misses the scene.
    const double truth_in_volume =
        WarnIfVolumeMissesTruth("score", name, truth.surface_mm, runtime.volume_center_mm(), options.volume_size_mm);
    // Hole filling runs with the mesh: only when the options ask for it.
    const bool fill = options.shape_model != ShapeModel::kNone;
    const std::vector<cv::Mat> images = LoadCapture((scene_dir / "active").string(), rig);
    const Reconstruction rec = runtime.Process(images, fill);
    const SceneScore s = ScoreScene(runtime, rec, truth);
    nlohmann::json sj = {
        {"scene", name},
        {"points", rec.cloud.size()},
        {"truth_in_volume", truth_in_volume},
        {"merged", ErrorFiguresJson(s.accuracy.all)},
        {"fill", FillJson(s.fill_all)},
        {"alignment_truth_from_cloud",
         {{"rotation_deg", s.accuracy.truth_from_cloud.AngleDeg()},
          {"translation_mm",
           {s.accuracy.truth_from_cloud.translation_mm().x(), s.accuracy.truth_from_cloud.translation_mm().y(),
            s.accuracy.truth_from_cloud.translation_mm().z()}}}}};
    std::printf("%-8s %7zu points, fill %5.1f%% of %6d px; merged %s", name.c_str(), rec.cloud.size(),
                100 * s.fill_all.fill(), s.fill_all.target_px, ErrorText(s.accuracy.all, " mm").c_str());
    for (size_t m = 0; m < s.fill.size(); ++m) {
      const ErrorFigures& e = s.accuracy.per_module[m];
      sj["modules"].push_back({{"module", m},
                               {"accuracy", ErrorFiguresJson(e)},
                               {"fill", FillJson(s.fill[m])},
                               {"points_seen_through", rec.modules[m].seen_through},
                               {"points_on_seen_through_surfaces", rec.modules[m].seen_through_surface}});
      std::printf("; m%zu fill %5.1f%% %s", m, 100 * s.fill[m].fill(), ErrorText(e, " mm").c_str());
    }
    if (!no_passive && fs::is_directory(scene_dir / "passive")) {
      const Reconstruction passive = passive_runtime.Process(LoadCapture((scene_dir / "passive").string(), rig), false);
      sj["passive_points"] = passive.cloud.size();
      if (passive.cloud.size() > 0) {
        const double ratio = double(rec.cloud.size()) / passive.cloud.size();
        sj["active_over_passive"] = ratio;
        // The ratio counts points, right or wrong: passive matches on weak
        // texture are often gross mismatches (the demo cup's: 40 % over 1 mm
        // off), so their figures, under the active cloud's alignment (a cloud
        // of mismatches would pull its own), say what the count is worth.
        const ErrorFigures p =
            ScoreUnderAlignment(passive.cloud, truth.surface_mm, s.accuracy.truth_from_cloud, int(s.fill.size())).all;
        sj["passive"] = ErrorFiguresJson(p);
        const double within = p.within_0_5_mm * p.points;
        sj["active_over_passive_within_0_5_mm"] =
            within > 0 ? nlohmann::json(s.accuracy.all.within_0_5_mm * s.accuracy.all.points / within) : nullptr;
        std::printf("; passive %zu points (%.0f%% within 0.5 mm, |e| %.3f mm; active/passive %.1fx)",
                    passive.cloud.size(), 100 * p.within_0_5_mm, p.mean_abs_mm, ratio);
      } else {  // no ratio to give: null, not 0 (which would read as "passive did better")
        sj["active_over_passive"] = nullptr;
        std::printf("; passive 0 points (no active/passive ratio)");
      }
    } else if (!no_passive) {
      std::printf("; no passive capture (%s)", (scene_dir / "passive").c_str());
    }
    std::printf("; aligned by %.4f deg, %.4f mm\n", s.accuracy.truth_from_cloud.AngleDeg(),
                s.accuracy.truth_from_cloud.translation_mm().norm());
    for (size_t m = 0; m < s.fill.size(); ++m) {
      std::printf("  m%zu lost: %s\n", m, LossLine(s.fill[m].target_status, s.fill[m].target_px).c_str());
      if (rec.modules[m].seen_through > 0)
        std::printf("  m%zu free-space test: %d points removed (seen through; %d of them with their surface)\n", m,
                    rec.modules[m].seen_through, rec.modules[m].seen_through_surface);
    }
    if (fill) {
      sj["shape_fit"] = rec.shape_fit;
      sj["hole_fill_ms"] = rec.times_ms.at("hole_fill");
      sj["filled"] = FilledJson(s.accuracy);
      std::printf("  %s\n", rec.shape_fit.c_str());
      std::printf("  filled %s (%.0f ms)\n", FilledLine(s.accuracy.filled).c_str(), rec.times_ms.at("hole_fill"));
      for (const FillBand& b : s.accuracy.filled_by_distance) {
        char band[48];
        std::snprintf(band, sizeof band, std::isfinite(b.to_mm) ? "%.0f-%.0f mm" : ">= %.0f mm", b.from_mm, b.to_mm);
        std::printf("    %-10s from measured: %s\n", band, FilledLine(b.figures).c_str());
      }
    }
    if (!diagnose_dir.empty()) {
      const std::vector<CameraTruthMaps> maps =
          ReadCameraTruthMaps((fs::path(dataset) / "truth" / "scenes" / name).string(), truth_rig.num_cameras());
      for (size_t m = 0; m < s.fill.size(); ++m) {
        const FillDiagnosis d = DiagnoseFill(runtime, int(m), images, rec, truth.fill_target[m],
                                             maps[truth_rig.module(int(m)).left_camera].depth_mm);
        const std::string prefix = FillDiagnosisPrefix(diagnose_dir, name, int(m));
        const std::vector<std::pair<std::string, std::string>> images_made = EncodeFillDiagnosisImages(d, prefix);
        for (const auto& [path, bytes] : images_made) written.Add(path, bytes);
        if (images_made.empty()) {
          // No match ROI (no lit pixel): an earlier run's images of the
          // module, left in DIR, would stand beside this run's as its own.
          for (const std::string& path : FillDiagnosisImagePaths(prefix)) earlier_images.push_back(path);
          std::printf("  m%zu diagnosis images: none (the module searched no pixel)\n", m);
        }
        std::printf("  m%zu diagnosis: %s", m, d.Summary().c_str());
      }
    }
    report["scenes"].push_back(sj);
    FlushStdout();  // each scene's lines as it is done (~3 s a scene), also into a pipe or a log file
  }
  if (!report_path.empty()) written.Add(report_path, JsonReportText(report) + "\n");
  written.Commit();
  for (const std::string& path : earlier_images) {
    std::error_code ec;
    if (!fs::remove(path, ec) && ec)
      std::fprintf(stderr, "score: warning: %s (an earlier run's) could not be removed: %s\n", path.c_str(),
                   ec.message().c_str());
  }
  if (!rig_given) WarnOfTruthRig("score", rig_path);
  return kExitOk;
}

}  // namespace stereorig
