#include "apps/reconstruct_stream.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "apps/reconstruct_capture.h"
#include "apps/stream_input.h"
#include "calib/core/folder_to_create.h"
#include "calib/core/input_error.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/runtime.h"

namespace stereorig {

namespace fs = std::filesystem;

namespace {

// Absolute and normal, without a trailing separator ("caps/0001/" is
// "caps/0001"); links not followed.
fs::path FolderPath(const std::string& dir) {
  fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
  if (!p.has_filename()) p = p.parent_path();
  return p;
}

// `p` below `root` ("" if it is not): a path holding no ".." and not ".".
fs::path PathBelow(const fs::path& p, const fs::path& root) {
  const fs::path below = p.lexically_relative(root);
  return below.empty() || below == "." || *below.begin() == ".." ? fs::path() : below;
}

}  // namespace

std::string StreamOutputName(const std::string& dir, const std::string& root) {
  const fs::path p = FolderPath(dir);
  if (root.empty()) {
    const std::string name = p.filename().string();
    if (name.empty()) throw InputError(dir, "a capture folder cannot be the file system's root");
    return name;
  }
  // As written first (a capture folder that is itself a link below the root
  // stays below it); else as the file system resolves both, so that a root
  // given through a link (or a folder sent through one) still holds it.
  fs::path below = PathBelow(p, FolderPath(root));
  if (below.empty()) below = PathBelow(ResolvedFolder(dir), ResolvedFolder(root));
  if (below.empty())
    throw InputError(dir, "is not a folder below --capture-root " + root + ", which names the captures");
  std::string name;
  for (const fs::path& c : below) {
    if (!name.empty()) name.push_back('_');
    name.append(c.string());
  }
  return name;
}

namespace {

using Clock = std::chrono::steady_clock;

// True, with *why set, once stdout has lost something written to it: a
// full disk or /dev/full, a terminal gone (EIO), a reader gone (EPIPE: the
// stream ignores SIGPIPE, so that a supervisor that died does not kill it
// between a capture's outputs and its summary). Each capture's line is the
// caller's answer, sent before the next folder is read: a stream that can
// no longer give them stops, as at the end of its input.
bool StdoutLost(std::string* why) {
  *why = StdoutWriteError();
  return !why->empty();
}

// At most this many failed captures are listed in the summary (the count is
// always whole): a stream may run for days, and its memory must not grow
// with it. Reconstructed captures are not listed; each has its own report.
constexpr int kMaxFailuresListed = 1000;

// The checks of one capture that need no decoding, in the order a user
// would fix them. Throws InputError naming the problem. `paths`: the run's
// protected inputs and claimed summary; the capture's own images are
// protected and its outputs claimed in a copy. An output that exists is
// never replaced: a line's measurements are its record, and a folder sent
// twice, two folders of one name (day-numbered folders under dated ones) or
// a run over an earlier run's output folder would otherwise overwrite them
// unseen. Asking the file system keeps the memory constant over a stream
// that runs for days.
void CheckStreamCapture(const std::string& dir, const std::string& name, const CaptureOutputs& outputs, const Rig& rig,
                        OutputPaths paths) {
  for (const std::string& path : {outputs.cloud, outputs.report, outputs.mesh}) {
    std::error_code ec;
    if (!path.empty() && fs::symlink_status(path, ec).type() != fs::file_type::not_found)
      throw InputError(dir, "its output " + path +
                                " exists already: a stream never replaces a measurement (this run's or an earlier "
                                "one's); name each capture's folder uniquely (it is named '" +
                                name +
                                "'; --capture-root names captures by their path below it), or write to "
                                "another --out-dir");
  }
  for (const std::string& image : CaptureImagePaths(dir, rig)) paths.Protect(image, "a capture image");
  paths.Claim(outputs.cloud, name + "'s cloud");
  paths.Claim(outputs.report, name + "'s report");
  if (!outputs.mesh.empty()) paths.Claim(outputs.mesh, name + "'s mesh");
}

}  // namespace

int ReconstructStream(const Rig& rig, const RuntimeOptions& options, const StreamRequest& request, int input_fd) {
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
  if (!request.capture_root.empty() && !fs::is_directory(request.capture_root))
    throw InputError(request.capture_root, "is not a folder (--capture-root: the captures' folders lie below it)");
  // Before the runtime: its pool's threads, started with it, inherit the
  // blocked stop signals (stream_input.h).
  StreamInput input(input_fd);
  const auto t_build = Clock::now();
  const Runtime runtime(rig, options);  // bad options for this rig: refused before anything is written
  const double build_ms = MsSince(t_build);
  double warm_up_ms = 0;
  if (!request.warm_up_dir.empty()) {
    // Its outputs are not written: it only pays the first capture's costs
    // (the heap's pages faulted in, the worker threads started) before the
    // line's first object comes.
    const auto t_warm = Clock::now();
    try {
      CheckCaptureFiles(request.warm_up_dir, rig);
      runtime.Process(LoadCaptureOrInputError(request.warm_up_dir, rig), !request.mesh_format.empty());
    } catch (const InputError& e) {  // named by its flag: "nope: capture folder not found" did not say which
      throw InputError("--warm-up", e.what());
    } catch (const fs::filesystem_error& e) {  // a path the file system cannot look up (a link loop)
      throw InputError("--warm-up", request.warm_up_dir + ": " + e.code().message());
    }
    warm_up_ms = MsSince(t_warm);
  }
  out_folder.Create();
  std::printf("runtime built in %.0f ms (%d modules)", build_ms, rig.num_modules());
  if (!request.warm_up_dir.empty())
    std::printf(", warmed up on %s in %.0f ms (not written)", request.warm_up_dir.c_str(), warm_up_ms);
  std::printf("; reading capture folders from standard input, one per line -> %s\n", request.out_dir.c_str());
  // A caller that cannot be answered is told before any capture: exit 2, no
  // new --out-dir, the earlier summary left.
  RequireStdoutWritten();

  nlohmann::json summary;
  summary["runtime_build_ms"] = build_ms;
  if (!request.warm_up_dir.empty()) summary["warm_up_ms"] = warm_up_ms;
  summary["failed_captures"] = nlohmann::json::array();  // the first kMaxFailuresListed
  int total = 0, failed = 0, without_points = 0, with_row_drift = 0;
  RowDriftWatch row_drift(runtime.options().match.line_index.max_row_offset_px);
  std::string output_error;  // why stdout lost a capture's line: the stream stops
  const auto t_all = Clock::now();
  std::string line;
  while (input.Next(&line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // written on Windows
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const auto t = Clock::now();
    if (total == 0 && !request.summary_path.empty()) {
      // A summary from an earlier run would describe that run until this
      // one ends: it goes with the first capture and is written anew at the
      // end (an input with no capture leaves it).
      std::error_code ec;
      fs::remove(request.summary_path, ec);
    }
    const std::string& dir = line;
    char progress[24];
    std::snprintf(progress, sizeof progress, "[%d]", ++total);
    std::string name;
    std::string error;
    try {
      if (dir.find('\0') != std::string::npos)
        throw InputError("line " + std::to_string(total), "holds a NUL byte: not a folder's path");
      name = StreamOutputName(dir, request.capture_root);
      CaptureOutputs outputs = CaptureOutputsNamed(request.out_dir, name, request.mesh_format);
      // Checked free below, and committed so that a file made meanwhile
      // (another stream writing to this --out-dir) is not replaced either:
      // the capture is then refused.
      outputs.at_existing = AtExisting::kRefuse;
      CheckStreamCapture(dir, name, outputs, rig, paths);
      CheckCaptureFiles(dir, rig);
      const std::vector<cv::Mat> images = LoadCaptureOrInputError(dir, rig);
      const nlohmann::json entry = ReconstructCapture(runtime, images, dir, name, outputs, progress, t, &row_drift);
      without_points += !entry["modules_without_points"].empty();
      with_row_drift += !entry["modules_with_row_drift"].empty();
      if (StdoutLost(&output_error)) break;
      continue;
    } catch (const InputError& e) {  // the capture's files, images or outputs
      error = e.what();
    } catch (const fs::filesystem_error& e) {  // a path the file system cannot look up (a link loop, too long)
      error = dir + ": " + e.code().message();
    }
    // A capture that failed wrote nothing (its outputs are committed all or
    // none, none over a file): no file of its name is removed, so neither is
    // one another run wrote there, nor an earlier one the check found.
    const nlohmann::json entry = FailedCapture(dir, name, CaptureOutputs{}, progress, error);
    if (++failed <= kMaxFailuresListed) summary["failed_captures"].push_back(entry);
    if (StdoutLost(&output_error)) break;
  }
  if (!output_error.empty()) {  // the captures' lines are the stream's answers: none can be given any more
    std::fprintf(stderr,
                 "stereorig reconstruct: standard output: cannot be written: %s; the stream stops after %d "
                 "capture%s, reading no further line ([%d]'s line was lost; its outputs, if it has any, are "
                 "written)\n",
                 output_error.c_str(), total, total == 1 ? "" : "s", total);
    summary["output_error"] = output_error;
  }
  if (!input.error().empty()) {  // the input ends here: what was read is done, the summary written
    std::fprintf(stderr, "stereorig reconstruct: standard input could not be read further: %s\n",
                 PrintableText(input.error()).c_str());
    summary["input_error"] = input.error();
  }
  const int stop = input.stop_signal();
  if (stop != 0) {
    // No capture done: none was in progress either. After one, the signal
    // may have come while the stream waited for a line (nothing in
    // progress) or during a capture that then failed (nothing written):
    // the line claims no more than that a capture in progress was finished.
    std::printf("stopped by %s after %d capture%s; no further line read%s\n", SignalName(stop).c_str(), total,
                total == 1 ? "" : "s", total == 0 ? "" : " (a capture in progress when it came, if any, was finished)");
    FlushStdout();
    summary["stopped_by"] = SignalName(stop);
  }
  if (total == 0) {
    out_folder.RemoveIfEmpty();
    if (stop != 0) return kExitOk;  // stopped before the line's first object: nothing to sum up
    throw InputError("--capture -", "standard input held no capture folder (one folder's path per line)");
  }
  const int code = FinishRun(&summary, total, failed, without_points, with_row_drift, row_drift, MsSince(t_all),
                             "the stream's wall time: waiting for the input, reading, reconstructing and writing",
                             request.summary_path);
  if (failed > 0) out_folder.RemoveIfEmpty();  // as a batch: nothing written, no new folder
  return output_error.empty() ? code : kExitBadInput;
}

}  // namespace stereorig
