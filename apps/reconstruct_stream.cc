#include "apps/reconstruct_stream.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "apps/output_paths.h"
#include "apps/reconstruct_capture.h"
#include "calib/core/folder_to_create.h"
#include "calib/core/input_error.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/runtime.h"

namespace stereorig {

namespace fs = std::filesystem;

namespace {

// The folder as a batch compares them (reconstruct_batch.h BatchOutputNames):
// absolute and normal, links not followed ("caps/0001/" is "caps/0001").
fs::path FolderKey(const std::string& dir) {
  fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
  if (!p.has_filename()) p = p.parent_path();
  return p;
}

}  // namespace

std::string StreamOutputName(const std::string& dir) {
  const std::string name = FolderKey(dir).filename().string();
  if (name.empty()) throw InputError(dir, "a capture folder cannot be the file system's root");
  return name;
}

namespace {

using Clock = std::chrono::steady_clock;

// What the stream has written so far, to refuse a capture that would replace
// it: by output name and by folder (FolderKey), the capture each came from.
struct Written {
  std::map<std::string, std::pair<int, std::string>> by_name;  // name -> (line, folder as given)
  std::map<fs::path, int> by_folder;                           // folder -> line
};

// The checks of one capture that need no decoding, in the order a user
// would fix them. Throws InputError naming the problem. `paths`: the run's
// protected inputs and claimed summary; the capture's own images are
// protected and its outputs claimed in a copy.
void CheckStreamCapture(const std::string& dir, const std::string& name, const CaptureOutputs& outputs, const Rig& rig,
                        const Written& written, OutputPaths paths) {
  if (const auto it = written.by_folder.find(FolderKey(dir)); it != written.by_folder.end())
    throw InputError(dir, "was given already (capture " + std::to_string(it->second) +
                              "): its outputs are written; a capture is reconstructed once per run");
  if (const auto it = written.by_name.find(name); it != written.by_name.end())
    throw InputError(dir, "would write outputs named '" + name + "', as " + it->second.second + " (capture " +
                              std::to_string(it->second.first) +
                              ") did: a stream names each capture by its folder's last name; rename the folder");
  for (const std::string& image : CaptureImagePaths(dir, rig)) paths.Protect(image, "a capture image");
  paths.Claim(outputs.cloud, name + "'s cloud");
  paths.Claim(outputs.report, name + "'s report");
  if (!outputs.mesh.empty()) paths.Claim(outputs.mesh, name + "'s mesh");
}

}  // namespace

int ReconstructStream(const Rig& rig, const RuntimeOptions& options, const StreamRequest& request, std::istream& in) {
  if (!request.mesh_format.empty() && request.mesh_format != "ply" && request.mesh_format != "stl")
    throw InputError("--mesh-format", "must be ply or stl, not '" + request.mesh_format + "'");
  OutputPaths paths("choose another --report");
  paths.Protect(request.rig_path, "the rig file (--rig)");
  paths.Protect(request.options_path, "the options file (--options)");
  FolderToCreate out_folder = paths.ClaimFolder(request.out_dir, "the output folder (--out-dir)");
  if (!request.summary_path.empty()) {
    paths.Claim(request.summary_path, "the summary (--report)", false);
    const fs::path folder = fs::absolute(fs::path(request.summary_path)).parent_path().lexically_normal();
    const fs::path out = fs::absolute(fs::path(request.out_dir)).lexically_normal();
    if (folder != out && !fs::is_directory(folder)) throw InputError(request.summary_path, "its folder does not exist");
  }
  const auto t_build = Clock::now();
  const Runtime runtime(rig, options);  // bad options for this rig: refused before anything is written
  const double build_ms = MsSince(t_build);
  out_folder.Create();
  std::error_code ec;
  // A summary from an earlier run would describe that run until this one
  // ends: it goes now and is written anew at the end.
  if (!request.summary_path.empty()) fs::remove(request.summary_path, ec);
  std::printf(
      "runtime built in %.0f ms (%d modules); reading capture folders from standard input, one per line -> %s\n",
      build_ms, rig.num_modules(), request.out_dir.c_str());
  std::fflush(stdout);

  nlohmann::json summary;
  summary["runtime_build_ms"] = build_ms;
  summary["captures"] = nlohmann::json::array();
  Written written;
  int total = 0, failed = 0;
  const auto t_all = Clock::now();
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // written on Windows
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const auto t = Clock::now();
    const std::string& dir = line;
    char progress[24];
    std::snprintf(progress, sizeof progress, "[%d]", ++total);
    std::string name;
    CaptureOutputs outputs;  // set once they are this capture's to write (or to remove)
    std::string error;
    try {
      name = StreamOutputName(dir);
      const CaptureOutputs planned = CaptureOutputsNamed(request.out_dir, name, request.mesh_format);
      // Refused here, nothing of the name is removed: it may be an earlier
      // capture's output or an input.
      CheckStreamCapture(dir, name, planned, rig, written, paths);
      outputs = planned;
      CheckCaptureFiles(dir, rig);
      const std::vector<cv::Mat> images = LoadCaptureOrInputError(dir, rig);
      summary["captures"].push_back(ReconstructCapture(runtime, images, dir, name, outputs, progress, t));
      written.by_name[name] = {total, dir};
      written.by_folder[FolderKey(dir)] = total;
      continue;
    } catch (const InputError& e) {  // the capture's files, images or outputs
      error = e.what();
    }
    ++failed;
    summary["captures"].push_back(FailedCapture(dir, name, outputs, progress, error));
  }
  if (total == 0) {
    out_folder.RemoveIfEmpty();
    throw InputError("--capture -", "standard input held no capture folder (one folder's path per line)");
  }
  const int code = FinishRun(&summary, total, failed, MsSince(t_all), request.summary_path);
  if (failed > 0) out_folder.RemoveIfEmpty();  // as a batch: nothing written, no new folder
  return code;
}

}  // namespace stereorig
