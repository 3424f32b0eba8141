#include "apps/demo_out.h"

#include <algorithm>
#include <filesystem>
#include <regex>
#include <vector>

#include "calib/core/folder_to_create.h"
#include "calib/core/input_error.h"
#include "datasets/simulate.h"

namespace stereorig {

namespace fs = std::filesystem;

bool DemoWrites(const std::string& name) {
  // As apps/cmd_demo.cc names them, step by step (simulate; calibrate;
  // reconstruct and score; verify; check), each between spaces;
  // camK.cameramodel, below, are calibrate's --export-cameramodels.
  static const std::string kNames =
      " dataset rig.yaml calibration.json passive_options.yaml cup_active.ply cup_active_mesh.ply cup_active.json"
      " cup_passive.ply cup_passive_mesh.ply cup_passive.json score_cup.json sphere.ply ballbar.ply"
      " verify_sphere.json verify_ballbar.json night_ok night_bumped check-history.sqlite check_ok.json"
      " check_bumped.json"
      // SQLite's own files beside the history, left by a check that was
      // interrupted (the demo deletes the history before its check step).
      " check-history.sqlite-journal check-history.sqlite-wal check-history.sqlite-shm ";
  if (name.find(' ') == std::string::npos && kNames.find(" " + name + " ") != std::string::npos) return true;
  static const std::regex kCameraModel("cam(0|[1-9][0-9]*)\\.cameramodel");
  return std::regex_match(name, kCameraModel);
}

void CheckDemoOut(const std::string& out) {
  const fs::path folder = NormalPath(out);
  std::error_code ec;
  if (!fs::is_directory(folder, ec) || fs::is_empty(folder, ec)) return;  // a file is ClaimFolder's to name
  std::vector<std::string> foreign;
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (!DemoWrites(name)) foreign.push_back(name);
  }
  if (!foreign.empty())
    throw InputError(out, "holds " + *std::min_element(foreign.begin(), foreign.end()) +
                              ", which the demo does not write; refusing to write into it (move it out, or choose "
                              "another --out)");
  if (!fs::is_directory(folder / "dataset"))
    throw InputError(out,
                     "is not an earlier demo's folder (no dataset/), yet holds files of the names the demo "
                     "writes; refusing to replace them (choose another --out)");
  // Step 1's simulate would refuse it only after the demo had begun.
  CheckReplaceableOut((fs::path(out) / "dataset").string(), folder / "dataset");
}

}  // namespace stereorig
