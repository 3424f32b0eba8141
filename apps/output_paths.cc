#include "apps/output_paths.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "calib/core/atomic_file.h"
#include "calib/core/capture_image_name.h"
#include "calib/core/input_error.h"
#include "reconstruct/runtime.h"

namespace stereorig {

namespace fs = std::filesystem;

void OutputPaths::Protect(const std::string& path, const std::string& what) {
  if (!path.empty()) inputs_.emplace(NormalPath(path), what);  // an output through a link to an input is that input
}

void OutputPaths::Claim(const std::string& path, const std::string& what, bool check_folder) {
  const fs::path key = NormalPath(path);
  if (const auto it = inputs_.find(key); it != inputs_.end())
    throw InputError(path, "is " + it->second + ": writing " + what + " there would overwrite an input");
  // A folder claimed before (ClaimFolder) is named as one: the claims of a
  // command that puts its files in that folder come after it.
  if (const auto it = folders_.find(key); it != folders_.end())
    throw InputError(path, "is a folder this command creates for " + it->second + ", not a file to write");
  if (const auto it = claimed_.find(key); it != claimed_.end()) {
    if (fs::is_directory(key)) throw InputError(path, "is the folder for " + it->second + ", not a file to write");
    throw InputError(
        path, "would be written twice (" + it->second + " and " + what + ")" + (remedy_.empty() ? "" : ": " + remedy_));
  }
  std::vector<fs::path> missing;
  const fs::path existing = DeepestExistingPart(key, &missing);
  CheckNamesFit(path, "write " + what, existing, missing);
  if (check_folder && !fs::is_directory(key.parent_path())) {
    // A file where the folder should be (--out rig.yaml/x) is named as one.
    const bool under_file = !existing.empty() && existing != key && !fs::is_directory(existing);
    throw InputError(path, under_file ? existing.string() + " is a file, not a folder" : "its folder does not exist");
  }
  // Found now, not when the file is written after the command's work. The
  // folder the path names, not its link's target's: the file is written
  // there (a temporary file renamed over the path, calib/core/atomic_file.h).
  const fs::path given_folder = fs::path(path).parent_path();
  const fs::path folder = given_folder.empty() ? fs::path(".") : given_folder;
  // Once per folder: a stream capture's cloud, report and mesh share one.
  if (check_folder && !writable_folders_.count(folder.lexically_normal())) {
    // access() first (no file made); then a file created and removed
    // there, for what access() cannot tell (root in /sys).
    std::string why = access(folder.c_str(), W_OK | X_OK) != 0 ? std::strerror(errno) : CannotCreateBeside(path);
    if (!why.empty())
      throw InputError(path,
                       "cannot write " + what + " in its folder " + folder.lexically_normal().string() + ": " + why);
    writable_folders_.insert(folder.lexically_normal());
  }
  if (fs::is_directory(key)) throw InputError(path, "is a folder, not a file to write");
  RequireReplaceableOutput(path);
  claimed_.emplace(key, what);
}

OutputPaths ClaimRuntimeReport(const RuntimeReportClaim& report) {
  OutputPaths outputs;
  outputs.Protect(report.rig_path, report.rig_what);
  outputs.Protect(report.options_path, "the options file (--options)");
  for (const auto& [path, what] : report.more_inputs) outputs.Protect(path, what);
  if (!report.path.empty()) outputs.Claim(report.path, "the report (--report)", report.check_folder);
  return outputs;
}

std::vector<std::pair<std::string, std::string>> DatasetInputs(const std::string& dataset) {
  std::vector<std::pair<std::string, std::string>> inputs;
  if (dataset.empty() || !fs::is_directory(dataset)) return inputs;
  const fs::path root(dataset);
  inputs.push_back({(root / "truth" / "rig.yaml").string(), "the dataset's truth rig file"});
  // The rest of the truth: surfaces, depth, id and lit maps, object poses.
  std::error_code ec;
  if (fs::is_directory(root / "truth"))
    for (auto it =
             fs::recursive_directory_iterator(root / "truth", fs::directory_options::follow_directory_symlink, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
      if (it->is_regular_file(ec) && it->path() != root / "truth" / "rig.yaml")
        inputs.push_back({it->path().string(), "a truth file of the dataset"});
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
  if (path == "-")  // as a file output's (RequireReplaceableOutput): "-" read as standard output
    throw InputError(path,
                     "outputs are folders and files, not standard output: name the folder (./- for one "
                     "called '-')");
  const fs::path key = NormalPath(path);
  if (const auto it = inputs_.find(key); it != inputs_.end())
    throw InputError(path, "is " + it->second + ", not a folder for " + what);
  if (const auto it = claimed_.find(key); it != claimed_.end())
    throw InputError(path, "is claimed by " + it->second + " as a file, not a folder for " + what);
  // The nearest part of the path that exists must be a folder: the command
  // creates the rest, none of which may be a file another output claimed
  // (--report a with --export-cameramodels a/b).
  std::vector<fs::path> missing;
  const fs::path existing = DeepestExistingPart(key, &missing);
  if (!existing.empty() && !fs::is_directory(existing))
    throw InputError(path, (existing == key ? std::string("is a file") : existing.string() + " is a file") +
                               ", not a folder for " + what);
  for (const fs::path& p : missing)
    if (const auto it = claimed_.find(p); it != claimed_.end())
      throw InputError(path, p.string() + " is claimed by " + it->second + " as a file, not a folder for " + what);
  // And the rest can be made, and written in: found now, not when the
  // folder is created after the command's work.
  CheckNamesFit(path, "create this folder for " + what, existing, missing);
  if (!existing.empty() && access(existing.c_str(), W_OK | X_OK) != 0) {
    const std::string why = std::strerror(errno);
    throw InputError(path, missing.empty()
                               ? "cannot write " + what + " in this folder: " + why
                               : "cannot create this folder for " + what + ": " + existing.string() + ": " + why);
  }
  for (const fs::path& p : missing) folders_.emplace(p, what);
  claimed_.emplace(key, what);
  return FolderToCreate(path, what);
}

void ProtectCaptureInputs(const std::string& rig_path, const std::string& options_path, const std::string& capture_dir,
                          const Rig& rig, OutputPaths* outputs) {
  outputs->Protect(rig_path, "the rig file (--rig)");
  outputs->Protect(options_path, "the options file (--options)");
  for (const std::string& image : CaptureImagePaths(capture_dir, rig))
    outputs->Protect(image, "a capture image (--capture)");
}

}  // namespace stereorig
