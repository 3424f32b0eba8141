#include "apps/reconstruct_batch.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <map>
#include <nlohmann/json.hpp>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "apps/reconstruct_capture.h"
#include "calib/core/input_error.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/runtime.h"

namespace stereorig {

namespace fs = std::filesystem;

std::vector<std::string> BatchOutputNames(const std::vector<std::string>& capture_dirs) {
  std::vector<std::vector<std::string>> parts;
  std::map<fs::path, std::string> seen;  // the folder (links followed) -> as given
  for (const std::string& dir : capture_dirs) {
    fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
    if (!p.has_filename()) p = p.parent_path();  // "caps/0001/" names 0001
    // One folder through two paths ("nm/q", "link_to_nm/q") would be
    // reconstructed twice: compared as the file system finds them.
    const fs::path folder = ResolvedFolder(dir);
    if (const auto it = seen.find(folder); it != seen.end())
      throw InputError("--capture", dir + " is given twice (as " + it->second + ")");
    seen.emplace(folder, dir);
    std::vector<std::string> components;
    for (const fs::path& c : p.relative_path()) components.push_back(c.string());
    if (components.empty()) throw InputError(dir, "a capture folder cannot be the file system's root");
    parts.push_back(std::move(components));
  }
  size_t shared = 0;  // components every path has in common, at least the last one of each kept
  if (!parts.empty()) {
    size_t shortest = parts[0].size();
    for (const auto& p : parts) shortest = std::min(shortest, p.size());
    while (shared + 1 < shortest &&
           std::all_of(parts.begin(), parts.end(), [&](const auto& p) { return p[shared] == parts[0][shared]; }))
      ++shared;
  }
  std::vector<std::string> names;
  std::map<std::string, size_t> by_name;
  for (size_t i = 0; i < parts.size(); ++i) {
    std::string name;
    for (size_t k = shared; k < parts[i].size(); ++k) name += (name.empty() ? "" : "_") + parts[i][k];
    if (const auto it = by_name.find(name); it != by_name.end())
      throw InputError("--capture", capture_dirs[it->second] + " and " + capture_dirs[i] +
                                        " would both write outputs named '" + name + "': rename one folder");
    by_name.emplace(name, i);
    names.push_back(name);
  }
  return names;
}

namespace {

using Clock = std::chrono::steady_clock;

// The output paths of every capture, and the summary's, checked before
// anything is written: no two the same file (folders "x" and "x.mesh" with
// --mesh-format ply; a --report naming a capture's own report), none one of
// the capture images read (a --report named caps/0001/cam0.png), and the
// summary's folder exists or is the output folder.
// `out_folder`: set to the output folder, to be created (FolderToCreate).
std::vector<CaptureOutputs> PlanOutputs(const std::vector<std::string>& names, const BatchRequest& request,
                                        const Rig& rig, FolderToCreate* out_folder) {
  std::vector<CaptureOutputs> outputs;
  OutputPaths paths("rename a folder or choose another --report");
  paths.Protect(request.rig_path, "the rig file (--rig)");
  paths.Protect(request.options_path, "the options file (--options)");
  for (const std::string& dir : request.capture_dirs)
    for (const std::string& image : CaptureImagePaths(dir, rig)) paths.Protect(image, "a capture image (--capture)");
  *out_folder = paths.ClaimFolder(request.out_dir, "the output folder (--out-dir)");  // not a file, nor under one
  // The output folder is created later, once everything is checked.
  auto claim = [&](const std::string& path, const std::string& what) { paths.Claim(path, what, false); };
  for (const std::string& name : names) {
    const CaptureOutputs o = CaptureOutputsNamed(request.out_dir, name, request.mesh_format);
    claim(o.cloud, name + "'s cloud");
    claim(o.report, name + "'s report");
    if (!o.mesh.empty()) claim(o.mesh, name + "'s mesh");
    outputs.push_back(o);
  }
  if (!request.summary_path.empty()) {
    claim(request.summary_path, "the summary (--report)");
    const fs::path folder = fs::absolute(fs::path(request.summary_path)).parent_path().lexically_normal();
    const fs::path out = fs::absolute(fs::path(request.out_dir)).lexically_normal();
    if (folder != out && !fs::is_directory(folder)) throw InputError(request.summary_path, "its folder does not exist");
  }
  AddEarlierMeshes(request.out_dir, request.mesh_format, {request.rig_path, request.options_path, request.summary_path},
                   &outputs);
  return outputs;
}

}  // namespace

int ReconstructBatch(const Rig& rig, const RuntimeOptions& options, const BatchRequest& request) {
  const std::vector<std::string>& dirs = request.capture_dirs;
  if (dirs.empty()) throw InputError("--capture", "no capture folder given");
  if (!request.mesh_format.empty() && request.mesh_format != "ply" && request.mesh_format != "stl")
    throw InputError("--mesh-format", "must be ply or stl, not '" + request.mesh_format + "'");
  // Everything that needs no decoding is checked before anything is written,
  // the runtime too (its options can still be bad input for this rig).
  const std::vector<std::string> names = BatchOutputNames(dirs);
  FolderToCreate out_folder;
  const std::vector<CaptureOutputs> outputs = PlanOutputs(names, request, rig, &out_folder);
  for (const std::string& dir : dirs) CheckCaptureFiles(dir, rig);
  auto load = [&rig](const std::string& dir) { return LoadCaptureOrInputError(dir, rig); };
  std::future<std::vector<cv::Mat>> next = std::async(std::launch::async, load, dirs[0]);  // while the runtime builds
  const auto t_build = Clock::now();
  const Runtime runtime(rig, options);
  const double build_ms = MsSince(t_build);
  out_folder.Create();
  std::error_code ec;
  // A summary from an earlier run would describe that run until this one
  // ends: it goes now and is written anew at the end.
  if (!request.summary_path.empty()) fs::remove(request.summary_path, ec);
  std::printf("runtime built in %.0f ms (%d modules); %zu captures -> %s\n", build_ms, rig.num_modules(), dirs.size(),
              request.out_dir.c_str());
  FlushStdout();

  nlohmann::json summary;
  summary["runtime_build_ms"] = build_ms;
  summary["captures"] = nlohmann::json::array();
  int failed = 0, without_points = 0, with_row_drift = 0;
  RowDriftWatch row_drift(runtime.options().match.line_index.max_row_offset_px);
  const auto t_all = Clock::now();
  for (size_t i = 0; i < dirs.size(); ++i) {
    const auto t = Clock::now();
    char progress[48];
    std::snprintf(progress, sizeof progress, "[%zu/%zu]", i + 1, dirs.size());
    std::vector<cv::Mat> images;
    std::string error;
    try {
      images = next.get();
    } catch (const InputError& e) {
      error = e.what();
    }
    if (i + 1 < dirs.size()) next = std::async(std::launch::async, load, dirs[i + 1]);
    if (error.empty()) {
      try {
        const nlohmann::json entry =
            ReconstructCapture(runtime, images, dirs[i], names[i], outputs[i], progress, t, &row_drift);
        without_points += !entry["modules_without_points"].empty();
        with_row_drift += !entry["modules_with_row_drift"].empty();
        summary["captures"].push_back(entry);
        continue;
      } catch (const InputError& e) {  // the writers' failures (atomic_file.h)
        error = e.what();
      }
    }
    // A capture that fails (bad images, or outputs that cannot be written)
    // has no output; the rest go on.
    ++failed;
    summary["captures"].push_back(FailedCapture(dirs[i], names[i], outputs[i], progress, error));
  }
  const int code = FinishRun(&summary, int(dirs.size()), failed, without_points, with_row_drift, row_drift,
                             MsSince(t_all), "reading, reconstructing and writing", request.summary_path);
  // Every capture failed and nothing was written in it (no summary there):
  // a new output folder goes again, as bad input found earlier leaves none.
  if (failed > 0) out_folder.RemoveIfEmpty();
  return code;
}

}  // namespace stereorig
