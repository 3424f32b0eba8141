// `stereorig calibrate`: target captures + target file + layout -> rig file +
// JSON report, through the three-stage engine (calib/calibrate.h). Exit 0 on
// success, 2 on bad usage or bad input (one line naming the file and the
// problem; nothing written).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "calib/calibrate.h"
#include "calib/capture_folder.h"
#include "calib/core/input_error.h"
#include "calib/core/printable_text.h"
#include "calib/layout_file.h"

namespace stereorig {

int RunCalibrate(int argc, char** argv) {
  CLI::App app{
      "Calibrate a multi-module stereo rig from captures of the (double-sided) target, in three stages: each "
      "camera's intrinsics with mrcal (PnP seed, staged solve, outlier rejection, projection uncertainty), each "
      "module's right_from_left as a joint solve, then the S matrix: Horn's absolute orientation between modules, "
      "refined by one Ceres bundle adjustment over every capture and camera (and the plate's back_from_front, under "
      "the target file's stated sigma). A plain one-sided chessboard works for a single module. The rig file "
      "records the board (its corners, squares, and back_from_front as calibrated), which stereorig check measures "
      "with.\n\n"
      "Captures: DIR/NNN/camK.png (or a dataset folder holding calibration/NNN/camK.png); hidden sub-folders and "
      "those holding no camK.png (camera models written beside the captures) are skipped, and named. Layout: which "
      "cameras "
      "form each module, e.g.\n  modules:\n    - {name: module0, left: 0, right: 1, face: front}\n    - {name: "
      "module1, left: 2, right: 3, face: back}\n('face' is optional; if given, a detection of the other face by "
      "that module is refused).\n\n"
      "Refuses with exit 2: too few views (or distinct board poses among them), all views fronto-parallel, a camera "
      "that never sees the board, images "
      "of the wrong size, a face seen by the wrong module; and, after the solve (the summary and the report written, "
      "the rig file not), a stage that did not converge (rms over --max-rms-px; stage 3 also when half its corners are "
      "off by more than sqrt(2 ln 2) x --max-rms-px, when a camera's corners are off by more than the noise stage 2 "
      "measured on them allows (a module that moved between captures), or when its solver stopped short, at "
      "--max-iterations or otherwise), a lens no camera has, or a plate "
      "whose back_from_front stage 3 moved far beyond the target file's stated sigma (the target file named).\n\n"
      "Exit codes: 0 ok (the rig file written); 2 bad usage or input, or a calibration refused as above.\n\n"
      "Example:\n  stereorig calibrate --captures data/calibration --target target.yaml --layout layout.yaml "
      "--out rig.yaml --report report.json",
      "stereorig calibrate"};
  std::string captures, target_path, layout_path, out_path, report_path, cameramodels_dir;
  CalibrationOptions options;
  options.progress = true;
  bool fixed_intrinsics = false;
  app.add_option("--captures", captures, "captures folder: NNN/camK.png")->required();
  app.add_option("--target", target_path, "target file (YAML, docs/targets.md)")->required();
  app.add_option("--layout", layout_path, "layout file (YAML): the modules and their cameras")->required();
  app.add_option("--out", out_path, "rig file to write (YAML)")->required()->check(NonEmptyPath());
  app.add_option("--report", report_path, "JSON report to write (every figure of every stage)")
      ->required()
      ->check(NonEmptyPath());
  app.add_option("--export-cameramodels", cameramodels_dir, "also write DIR/camK.cameramodel (mrcal format)")
      ->check(NonEmptyPath());
  app.add_option("--lensmodel", options.intrinsics.lensmodel,
                 "LENSMODEL_OPENCV5 or LENSMODEL_OPENCV4 (solved without regularisation), or LENSMODEL_OPENCV8, "
                 "LENSMODEL_OPENCV12 or LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=.._Ny=.._fov_x_deg=.. (these keep "
                 "mrcal's regularisation); not LENSMODEL_PINHOLE (docs/calibration.md)")
      ->capture_default_str();
  app.add_option("--focal", options.intrinsics.seed_focal_px, "rough focal length for the PnP seed, px (0: estimate)")
      ->capture_default_str()
      ->check(NonNegativeValue());
  app.add_option("--uncertainty-range", options.intrinsics.uncertainty_range_mm,
                 "range of the points whose projection uncertainty is reported (and the nightly check's thresholds "
                 "come from), mm; 0: each camera's median distance to the board in its views, where the rig measures")
      ->capture_default_str()
      ->check(NonNegativeValue());
  app.add_option(
         "--max-rms-px", options.intrinsics.max_rms_px,
         "a stage whose reprojection rms is over this did not converge, px: stage 1 then solves again from its "
         "other seeds, and no rig file is written while a stage stays over it (a converged camera shows its "
         "corners' noise, a few tenths of a px at most); stage 3's median corner distance is held to sqrt(2 ln 2) "
         "times it, the median distance of corners whose coordinates have this rms, and each camera's to its "
         "stage 2 noise and as much again, or a tenth of this where that noise is less: a floor that grows with "
         "it (at 10, a module moved 1 mm between captures passes) and on low-noise corners passes a bias in S of "
         "a few of its sigmas")
      ->capture_default_str()
      ->check(PositiveValue());
  AddCountOption(app, "--max-iterations", &options.system.max_iterations,
                 "stage 3's Ceres iteration limit for each of its solves: a full adjustment that reaches it did not "
                 "converge (no rig file is written), a Horn-only solve that does is warned of");
  app.add_option("--huber", options.system.huber_px, "stage 3 robust loss scale, px")
      ->capture_default_str()
      ->check(PositiveValue());
  app.add_flag("--fixed-intrinsics", fixed_intrinsics, "hold the intrinsics at stage 2's values in stage 3");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  options.system.refine_intrinsics = !fixed_intrinsics;
  try {
    options.Check();
  } catch (const InputError& e) {
    // The library names its options' fields; the user gave them as flags.
    // The flags' own checks (above) catch the rest before this.
    if (e.where() != "options.lensmodel") throw;
    throw InputError("--lensmodel", e.problem());
  }
  // Checked before the calibration runs (minutes): a rig file and a report
  // at one path, or in a folder that is not there, would fail only at the end.
  OutputPaths outputs;
  outputs.Protect(target_path, "the target file (--target)");
  outputs.Protect(layout_path, "the layout file (--layout)");
  for (const std::string& image : CaptureFolderImages(captures)) outputs.Protect(image, "a capture image (--captures)");
  outputs.Claim(out_path, "the rig file (--out)");
  outputs.Claim(report_path, "the report (--report)");
  FolderToCreate models_folder;  // made once the calibration has succeeded
  if (!cameramodels_dir.empty())
    models_folder = outputs.ClaimFolder(cameramodels_dir, "the camera models (--export-cameramodels)");
  // Read once, here: the calibration's modules, and the cameras whose models
  // --export-cameramodels writes.
  const std::vector<ModuleLayout> layout = ReadLayoutFile(layout_path);
  std::vector<std::string> model_paths;  // camK.cameramodel for every camera of the layout
  if (!cameramodels_dir.empty()) {
    // Each model file too: a rig file named DIR/cam0.cameramodel would be
    // replaced by a model.
    for (int k = 0, n = LayoutCameraCount(layout); k < n; ++k) {
      model_paths.push_back(
          (std::filesystem::path(cameramodels_dir) / ("cam" + std::to_string(k) + ".cameramodel")).string());
      outputs.Claim(model_paths.back(), "camera " + std::to_string(k) + "'s model (--export-cameramodels)", false);
    }
  }

  FolderCalibration folder = CalibrateCaptureFolder(captures, target_path, layout, options);
  const CalibrationResult& result = folder.result;
  // Models of another rig in the models' folder: warned of and kept in the
  // report's warnings, as every warning calibrate prints is.
  // Only on a run that writes its models: a refused one writes none there.
  const bool writes = result.report.not_converged.empty() && result.report.wrong_plate.empty();
  if (const std::string note =
          cameramodels_dir.empty() || !writes ? "" : OtherCameramodelsNote(cameramodels_dir, model_paths);
      !note.empty()) {
    std::fprintf(stderr, "calibrate: warning: %s\n", PrintableText(note).c_str());
    folder.result.report.warnings.push_back(note);
  }
  // The models' folder first: one that cannot be made leaves no rig file
  // or report behind either.
  models_folder.Create();
  // Sub-folders taken for no capture are named, that a capture hidden or
  // left without its images by mistake is noticed.
  for (const std::string& skipped : folder.skipped_folders)
    std::printf("skipped %s: not a capture (a hidden folder, or one holding no camK.png)\n",
                PrintableText(skipped).c_str());
  // The summary first: a calibration whose rig file is refused (a lens no
  // camera has) still shows what it found.
  std::printf("%s", SummaryText(result.report).c_str());
  FlushStdout();
  WriteCalibrationOutputs(result, out_path, report_path, cameramodels_dir);
  // Every file written is named: the models too, by their folder (their
  // names are camK.cameramodel, one per camera of the layout).
  if (cameramodels_dir.empty()) {
    std::printf("wrote %s and %s\n", out_path.c_str(), report_path.c_str());
  } else {
    std::printf("wrote %s, %s and %d camera models (camK.cameramodel) in %s\n", out_path.c_str(), report_path.c_str(),
                LayoutCameraCount(layout), cameramodels_dir.c_str());
  }
  return 0;
}

}  // namespace stereorig
