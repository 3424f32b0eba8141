#include "apps/output_paths.h"

#include "calib/core/capture_image_name.h"
#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// The file a path names: symbolic links followed as far as the path exists
// (an output through a link to an input is that input), the rest normalised.
std::filesystem::path Key(const std::string& path) {
  return std::filesystem::weakly_canonical(std::filesystem::absolute(std::filesystem::path(path)));
}

}  // namespace

void OutputPaths::Protect(const std::string& path, const std::string& what) {
  if (!path.empty()) inputs_.emplace(Key(path), what);
}

void OutputPaths::Claim(const std::string& path, const std::string& what, bool check_folder) {
  namespace fs = std::filesystem;
  const fs::path key = Key(path);
  if (const auto it = inputs_.find(key); it != inputs_.end())
    throw InputError(path, "is " + it->second + ": writing " + what + " there would overwrite an input");
  if (const auto it = claimed_.find(key); it != claimed_.end())
    throw InputError(
        path, "would be written twice (" + it->second + " and " + what + ")" + (remedy_.empty() ? "" : ": " + remedy_));
  if (const auto it = folders_.find(key); it != folders_.end())
    throw InputError(path, "is a folder this command creates for " + it->second + ", not a file to write");
  if (check_folder && !fs::is_directory(key.parent_path())) throw InputError(path, "its folder does not exist");
  if (fs::is_directory(key)) throw InputError(path, "is a folder, not a file to write");
  claimed_.emplace(key, what);
}

void ClaimRuntimeReport(const std::string& report_path, const std::string& rig_path, const std::string& options_path,
                        bool check_folder, const std::string& rig_what,
                        const std::vector<std::pair<std::string, std::string>>& more_inputs,
                        const std::vector<std::pair<std::string, std::string>>& more_outputs) {
  OutputPaths outputs;
  outputs.Protect(rig_path, rig_what);
  outputs.Protect(options_path, "the options file (--options)");
  for (const auto& [path, what] : more_inputs) outputs.Protect(path, what);
  if (!report_path.empty()) outputs.Claim(report_path, "the report (--report)", check_folder);
  for (const auto& [path, what] : more_outputs) outputs.Claim(path, what, false);
}

std::vector<std::pair<std::string, std::string>> DatasetInputs(const std::string& dataset) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::string>> inputs;
  if (dataset.empty() || !fs::is_directory(dataset)) return inputs;
  const fs::path root(dataset);
  inputs.push_back({(root / "truth" / "rig.yaml").string(), "the dataset's truth rig file"});
  inputs.push_back({(root / "spec.yaml").string(), "the dataset's spec"});
  if (fs::is_directory(root / "scenes")) {
    for (const auto& scene : fs::directory_iterator(root / "scenes")) {
      for (const char* mode : {"active", "passive"}) {
        const fs::path capture = scene.path() / mode;
        if (!fs::is_directory(capture)) continue;
        for (const auto& e : fs::directory_iterator(capture))
          if (CameraIndexOfImageName(e.path().filename().string()))
            inputs.push_back({e.path().string(), "a capture image of the dataset"});
      }
    }
  }
  return inputs;
}

FolderToCreate OutputPaths::ClaimFolder(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  const fs::path key = Key(path);
  if (const auto it = inputs_.find(key); it != inputs_.end())
    throw InputError(path, "is " + it->second + ", not a folder for " + what);
  if (const auto it = claimed_.find(key); it != claimed_.end())
    throw InputError(path, "is claimed by " + it->second + " as a file, not a folder for " + what);
  // The nearest part of the path that exists must be a folder: the command
  // creates the rest, none of which may be a file another output claimed
  // (--report a with --export-cameramodels a/b).
  std::vector<fs::path> missing;
  for (fs::path p = key; !p.empty(); p = p.parent_path()) {
    if (fs::exists(p)) {
      if (!fs::is_directory(p))
        throw InputError(
            path, (p == key ? std::string("is a file") : p.string() + " is a file") + ", not a folder for " + what);
      break;
    }
    if (const auto it = claimed_.find(p); it != claimed_.end())
      throw InputError(path, p.string() + " is claimed by " + it->second + " as a file, not a folder for " + what);
    missing.push_back(p);
    if (p == p.root_path()) break;
  }
  for (const fs::path& p : missing) folders_.emplace(p, what);
  claimed_.emplace(key, what);
  return FolderToCreate(path, what);
}

}  // namespace stereorig
