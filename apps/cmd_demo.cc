// `stereorig demo`: every stage built so far, on the embedded default rig.
#include <cstdio>
#include <filesystem>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "calib/capture_folder.h"
#include "calib/core/cameramodel_export.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "calib/rig_compare.h"
#include "calib/synthetic.h"
#include "datasets/default_rig.h"
#include "datasets/sim_spec.h"
#include "datasets/simulate.h"

namespace stereorig {

void PrintRigSummary(const Rig& rig, FILE* out);

int RunDemo(int argc, char** argv) {
  CLI::App app{
      "Run every stage built so far on the embedded default rig (2 facing modules, 752x582 cameras, 90 mm "
      "baseline, 200 mm working distance) and print the figures.\n\n"
      "Example:\n  stereorig demo --out /tmp/stereorig-demo",
      "stereorig demo"};
  std::string out_dir = "stereorig-demo";
  app.add_option("--out", out_dir, "folder for everything the demo writes (created if missing)")->capture_default_str();
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) throw InputError(out_dir, "cannot create folder: " + ec.message());

  std::printf("== stage: the default rig (ground truth)\n");
  SimulatedRig sim = MakeDefaultRig();
  sim.rig.provenance().date_utc = NowUtcIso8601();
  PrintRigSummary(sim.rig, stdout);

  const std::string rig_path = (std::filesystem::path(out_dir) / "truth_rig.yaml").string();
  WriteRigFile(sim.rig, rig_path);
  const Rig back = ReadRigFile(rig_path);
  const bool identical = RigToYaml(back) == RigToYaml(sim.rig);
  std::printf("wrote %s; read back and re-written: %s\n", rig_path.c_str(),
              identical ? "bit-identical" : "DIFFERENT (bug)");
  for (int i = 0; i < back.num_cameras(); ++i) {
    const std::string path = (std::filesystem::path(out_dir) / (back.camera_names()[i] + ".cameramodel")).string();
    WriteCameramodel(back.camera(i), back.CamFromReference(i), path);
  }
  std::printf("exported %d .cameramodel files to %s\n", back.num_cameras(), out_dir.c_str());

  std::printf("== stage: simulate the default dataset (stereorig simulate --out %s/dataset --seed 1)\n",
              out_dir.c_str());
  SimulateOptions sim_options;
  sim_options.out_dir = (std::filesystem::path(out_dir) / "dataset").string();
  sim_options.seed = 1;
  sim_options.progress = [](const std::string& s) { std::fprintf(stderr, "simulate: %s\n", s.c_str()); };
  const SimulateSummary summary = Simulate(DefaultSimSpec(), sim_options);
  std::printf("wrote %s: %d images in %.1f s\n", sim_options.out_dir.c_str(), summary.images, summary.seconds);

  const std::filesystem::path dataset(sim_options.out_dir);
  const std::string calibrated_path = (std::filesystem::path(out_dir) / "rig.yaml").string();
  const std::string report_path = (std::filesystem::path(out_dir) / "calibration_report.json").string();
  std::printf(
      "== stage: calibrate it (stereorig calibrate --captures %s --target %s --layout %s --out %s --report %s)\n",
      dataset.string().c_str(), (dataset / "target.yaml").string().c_str(), (dataset / "layout.yaml").string().c_str(),
      calibrated_path.c_str(), report_path.c_str());
  CalibrationOptions calibration_options;
  calibration_options.progress = true;
  const FolderCalibration calibration = CalibrateCaptureFolder(dataset.string(), (dataset / "target.yaml").string(),
                                                               (dataset / "layout.yaml").string(), calibration_options);
  WriteCalibrationOutputs(calibration.result, calibrated_path, report_path);
  std::printf("%s", SummaryText(calibration.result.report).c_str());
  // Against the truth, by what users measure: each module's 3D error in the
  // volume after rigid alignment, and the modules' agreement through S.
  const Rig truth = ReadRigFile((dataset / "truth" / "rig.yaml").string());
  const Rig& calibrated = calibration.result.rig;
  const auto points = VolumePoints(sim.world_from_module0.Inverse(), Eigen::Vector3d(75, 75, 50), 2000, 1);
  std::printf("against the truth (points filling the 150 x 150 x 100 mm volume):\n");
  for (int k = 0; k < truth.num_modules(); ++k) {
    std::vector<Eigen::Vector3d> pc, pt;
    TriangulateThroughModule(truth, calibrated, k, points, &pc, &pt);
    std::printf("  module %d: 3D error after rigid alignment %.4f mm RMS (%zu points)\n", k, RigidAlignedRms(pt, pc),
                pc.size());
  }
  for (int i = 0; i < truth.num_modules(); ++i)
    for (int j = i + 1; j < truth.num_modules(); ++j) {
      std::printf("  modules %d-%d: agreement through S %.4f mm RMS\n", i, j,
                  ModuleAgreementRms(truth, calibrated, calibrated.S(i, j), i, j, points));
    }
  return identical ? kExitOk : kExitCheckFailed;
}

}  // namespace stereorig
