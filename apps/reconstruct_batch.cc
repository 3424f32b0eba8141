#include "apps/reconstruct_batch.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <map>
#include <nlohmann/json.hpp>

#include "apps/command.h"
#include "apps/module_summary.h"
#include "apps/output_paths.h"
#include "apps/reconstruct_json.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/ply_io.h"
#include "reconstruct/runtime.h"

namespace stereorig {

namespace fs = std::filesystem;

std::vector<std::string> BatchOutputNames(const std::vector<std::string>& capture_dirs) {
  std::vector<std::vector<std::string>> parts;
  std::map<fs::path, std::string> seen;  // normal absolute path -> as given
  for (const std::string& dir : capture_dirs) {
    fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
    if (!p.has_filename()) p = p.parent_path();  // "caps/0001/" names 0001
    if (const auto it = seen.find(p); it != seen.end())
      throw InputError("--capture", dir + " is given twice (as " + it->second + ")");
    seen.emplace(p, dir);
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

// Every file the batch writes, by capture: cloud, report, mesh ("" if none).
struct CaptureOutputs {
  std::string cloud, report, mesh;
};

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
    const std::string stem = (fs::path(request.out_dir) / name).string();
    CaptureOutputs o{stem + ".ply", stem + ".json", ""};
    claim(o.cloud, name + "'s cloud");
    claim(o.report, name + "'s report");
    if (!request.mesh_format.empty()) {
      o.mesh = stem + ".mesh." + request.mesh_format;
      claim(o.mesh, name + "'s mesh");
    }
    outputs.push_back(o);
  }
  if (!request.summary_path.empty()) {
    claim(request.summary_path, "the summary (--report)");
    const fs::path folder = fs::absolute(fs::path(request.summary_path)).parent_path().lexically_normal();
    const fs::path out = fs::absolute(fs::path(request.out_dir)).lexically_normal();
    if (folder != out && !fs::is_directory(folder)) throw InputError(request.summary_path, "its folder does not exist");
  }
  return outputs;
}

// LoadCapture, any failure as bad input naming the folder (a folder removed
// or made unreadable after the first check throws filesystem_error).
std::vector<cv::Mat> LoadCaptureOrInputError(const std::string& dir, const Rig& rig) {
  try {
    return LoadCapture(dir, rig);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(dir, std::string("cannot read the capture: ") + e.what());
  }
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
  std::fflush(stdout);

  const bool mesh = !request.mesh_format.empty();
  nlohmann::json summary;
  summary["runtime_build_ms"] = build_ms;
  summary["captures"] = nlohmann::json::array();
  int failed = 0;
  const auto t_all = Clock::now();
  for (size_t i = 0; i < dirs.size(); ++i) {
    const auto t = Clock::now();
    nlohmann::json entry;
    entry["capture"] = dirs[i];
    entry["name"] = names[i];
    std::vector<cv::Mat> images;
    std::string error;
    try {
      images = next.get();
    } catch (const InputError& e) {
      error = e.what();
    }
    if (i + 1 < dirs.size()) next = std::async(std::launch::async, load, dirs[i + 1]);
    // A capture that fails (bad images, or outputs that cannot be written)
    // has no output: not a partial one, nor a stale one from an earlier run.
    // The rest go on.
    auto fail = [&](const std::string& why) {
      ++failed;
      std::fprintf(stderr, "stereorig reconstruct: [%zu/%zu] %s\n", i + 1, dirs.size(), why.c_str());
      for (const std::string& path : {outputs[i].cloud, outputs[i].report, outputs[i].mesh})
        if (!path.empty()) fs::remove(path, ec);
      entry["ok"] = false;
      entry["error"] = why;
      summary["captures"].push_back(entry);
    };
    if (!error.empty()) {
      fail(error);
      continue;
    }
    const Reconstruction rec = runtime.Process(images, mesh);
    const std::string& cloud_path = outputs[i].cloud;
    try {
      WriteCloudPly(rec.cloud, cloud_path);
      if (mesh) WriteMesh(rec.mesh, outputs[i].mesh);
      WriteFileAtomically(outputs[i].report, ReconstructionJson(rec).dump(2) + "\n");
    } catch (const InputError& e) {  // the writers' failures (atomic_file.h)
      fail(e.what());
      continue;
    }
    entry["cloud"] = cloud_path;
    if (mesh) entry["mesh"] = outputs[i].mesh;
    entry["report"] = outputs[i].report;
    entry["ok"] = true;
    entry["points"] = rec.cloud.size();
    entry["point_cloud_ms"] = rec.times_ms.at("total_point_cloud");
    const double wall_ms = MsSince(t);  // waiting for the images, reconstructing, writing
    entry["wall_ms"] = wall_ms;
    std::string fills;
    for (const ModuleReport& m : rec.modules) {
      char buf[48];
      std::snprintf(buf, sizeof buf, "%sm%d %.1f%%", fills.empty() ? "" : ", ", m.module, 100 * m.fill_rate());
      fills += buf;
    }
    std::printf("[%zu/%zu] %s: %zu points (fill %s), %.0f ms -> %s\n", i + 1, dirs.size(), dirs[i].c_str(),
                rec.cloud.size(), fills.c_str(), wall_ms, cloud_path.c_str());
    // The one-capture summary's warning (module_summary.h), in a line per
    // module: a batch is what a line runs.
    for (const ModuleReport& m : rec.modules) {
      const std::string which = RangeEndsWarnedOf(m);
      if (!which.empty())
        std::printf(
            "  warning: module %d's matches reach %s of the measurement volume's disparity range (%s: "
            "range_end_reached): its points may lie where nothing is; check the volume\n",
            m.module, which.c_str(), outputs[i].report.c_str());
    }
    std::fflush(stdout);
    summary["captures"].push_back(entry);
  }
  const double all_ms = MsSince(t_all);
  const int done = int(dirs.size()) - failed;
  summary["reconstructed"] = done;
  summary["failed"] = failed;
  summary["wall_ms"] = all_ms;
  summary["objects_per_s"] = done > 0 ? 1000.0 * done / all_ms : 0.0;
  std::printf("%d of %zu captures in %.2f s: %.1f objects/s (reading, reconstructing and writing)\n", done, dirs.size(),
              all_ms / 1000, summary["objects_per_s"].get<double>());
  if (!request.summary_path.empty()) WriteFileAtomically(request.summary_path, summary.dump(2) + "\n");
  if (failed > 0) {
    // Every capture failed and nothing was written in it (no summary
    // there): a new output folder goes again, as bad input found earlier
    // leaves none.
    out_folder.RemoveIfEmpty();
    std::fprintf(stderr,
                 "stereorig reconstruct: %d of %zu captures failed (bad input, or outputs that could not be "
                 "written) and have no output\n",
                 failed, dirs.size());
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace stereorig
