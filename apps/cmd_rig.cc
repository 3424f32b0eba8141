// `stereorig rig`: validate a rig file, print a summary, export cameras.
#include <cstdio>
#include <filesystem>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "calib/core/cameramodel_export.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"

namespace stereorig {

void PrintRigSummary(const Rig& rig, FILE* out) {
  std::fprintf(out, "%d camera(s), %d module(s)\n", rig.num_cameras(), rig.num_modules());
  for (int i = 0; i < rig.num_cameras(); ++i) {
    const Camera& c = rig.camera(i);
    std::fprintf(out, "  camera %d %-6s %s %dx%d  fx %.2f fy %.2f cx %.2f cy %.2f px\n", i,
                 rig.camera_names()[i].c_str(), c.lensmodel_name().c_str(), c.imager_width_px(), c.imager_height_px(),
                 c.fx(), c.fy(), c.cx(), c.cy());
  }
  for (int i = 0; i < rig.num_modules(); ++i) {
    const StereoModule& m = rig.module(i);
    std::fprintf(out, "  module %d %-8s cameras %d,%d  baseline %.4f mm  right_from_left rotation %.4f deg\n", i,
                 m.name.c_str(), m.left_camera, m.right_camera, m.right_from_left.DistanceMm(),
                 m.right_from_left.AngleDeg());
  }
  for (int i = 0; i < rig.num_modules(); ++i) {
    for (int j = i + 1; j < rig.num_modules(); ++j) {
      std::fprintf(out, "  S[%d][%d] module%d_from_module%d: %.4f mm, %.4f deg\n", i, j, i, j, rig.S(i, j).DistanceMm(),
                   rig.S(i, j).AngleDeg());
    }
  }
}

int RunRig(int argc, char** argv) {
  CLI::App app{
      "Validate a rig file (every key, rotation and the S invariants), print a summary, and optionally export "
      "each camera as an mrcal .cameramodel (extrinsics relative to module 0).\n\n"
      "Example:\n  stereorig rig --rig out/rig.yaml --export-cameramodels out/models/",
      "stereorig rig"};
  std::string rig_path, export_dir;
  app.add_option("--rig", rig_path, "rig file (YAML, docs/formats.md)")->required();
  app.add_option("--export-cameramodels", export_dir, "folder to write camN.cameramodel files into");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  const Rig rig = ReadRigFile(rig_path);
  PrintRigSummary(rig, stdout);
  if (!export_dir.empty()) {
    if (!std::filesystem::is_directory(export_dir)) throw InputError(export_dir, "not a folder");
    for (int i = 0; i < rig.num_cameras(); ++i) {
      const std::string path = (std::filesystem::path(export_dir) / (rig.camera_names()[i] + ".cameramodel")).string();
      WriteCameramodel(rig.camera(i), rig.CamFromReference(i), path);
      std::printf("wrote %s\n", path.c_str());
    }
  }
  return kExitOk;
}

}  // namespace stereorig
