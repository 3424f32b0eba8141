#include "apps/reconstruct_capture.h"

#include <cstdio>
#include <filesystem>
#include <set>
#include <utility>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/module_summary.h"
#include "apps/ply_cloud_file.h"
#include "apps/reconstruct_json.h"
#include "calib/core/atomic_file.h"
#include "calib/core/folder_to_create.h"
#include "calib/core/input_error.h"
#include "calib/json_text.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/ply_io.h"

namespace stereorig {

namespace fs = std::filesystem;

CaptureOutputs CaptureOutputsNamed(const std::string& out_dir, const std::string& name,
                                   const std::string& mesh_format) {
  const std::string stem = (fs::path(out_dir) / name).string();
  return {stem + ".ply", stem + ".json", mesh_format.empty() ? "" : stem + ".mesh." + mesh_format};
}

void AddEarlierMeshes(const std::string& out_dir, const std::string& mesh_format, const std::vector<std::string>& also,
                      std::vector<CaptureOutputs>* outputs) {
  std::set<fs::path> used;  // as the file system resolves them
  for (const std::string& path : also)
    if (!path.empty()) used.insert(NormalPath(path));
  for (const CaptureOutputs& o : *outputs)
    for (const std::string& path : {o.cloud, o.report, o.mesh})
      if (!path.empty()) used.insert(NormalPath(path));
  for (CaptureOutputs& o : *outputs) {
    const std::string name = fs::path(o.cloud).stem().string();  // <name>.ply
    for (const std::string format : {"ply", "stl"}) {
      const std::string mesh = CaptureOutputsNamed(out_dir, name, format).mesh;
      if (format != mesh_format && !used.count(NormalPath(mesh))) o.earlier_only.push_back(mesh);
    }
  }
}

fs::path ResolvedFolder(const std::string& dir) {
  fs::path p = NormalPath(dir);  // links followed as far as they resolve (calib/core/folder_to_create.h)
  if (!p.has_filename()) p = p.parent_path();
  return p;
}

std::vector<cv::Mat> LoadCaptureOrInputError(const std::string& dir, const Rig& rig) {
  try {
    return LoadCapture(dir, rig);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(dir, std::string("cannot read the capture: ") + e.what());
  }
}

namespace {

// Removes each of `paths` that exists ("" skipped; a folder too, which no
// run wrote: a file only). Returns those that could not be removed, with why.
std::vector<std::pair<std::string, std::string>> RemoveEarlierFiles(const std::vector<std::string>& paths) {
  std::vector<std::pair<std::string, std::string>> left;
  for (const std::string& path : paths) {
    std::error_code ec;
    if (path.empty() || fs::is_directory(fs::symlink_status(path, ec)) || fs::remove(path, ec) || !ec) continue;
    left.emplace_back(path, ec.message());
  }
  return left;
}

// Of an earlier run's files of a capture's name (CaptureOutputs::
// earlier_only), those that are meshes: not a PLY cloud (IsPlyCloudFile).
// A capture "x.mesh" of an earlier run (or of another batch into this
// --out-dir) has its cloud at x.mesh.ply, where capture x's mesh would be:
// removing it for x left x.mesh.json without its cloud.
std::vector<std::string> EarlierMeshes(const std::vector<std::string>& earlier_only) {
  std::vector<std::string> meshes;
  for (const std::string& path : earlier_only)
    if (!IsPlyCloudFile(path)) meshes.push_back(path);
  return meshes;
}

// A module that gave no point (its lasers off, a camera not triggered, its
// cables swapped) is a capture that measured nothing there, not a
// measurement: a warning line after the capture's own on stdout, where the
// line's controller reads each capture's answer, and on stderr, where a
// log keeps the problems. Returns the modules', for the run's summary.
nlohmann::json WarnOfModulesWithoutPoints(const Reconstruction& rec, bool passive, const std::string& dir,
                                          const CaptureOutputs& outputs, const std::string& progress) {
  nlohmann::json modules = nlohmann::json::array();
  for (const ModuleReport& m : rec.modules) {
    const std::string why = NoPointReason(m, passive);
    if (why.empty()) continue;
    modules.push_back(m.module);
    std::printf("  warning: module %d gave no point (%s): %s\n", m.module, PrintableText(outputs.report).c_str(),
                why.c_str());
    std::fprintf(stderr, "stereorig reconstruct: %s %s: warning: module %d gave no point: %s\n", progress.c_str(),
                 PrintableText(dir).c_str(), m.module, why.c_str());
  }
  return modules;
}

// The run's verdict on a module's rows (RowDriftWatch) in the capture's
// report beside the capture's own `row_drift`, which judges this capture's
// reading alone: a report read on its own must not say "not warned" where
// the run warned of the module at that capture.
nlohmann::json RowDriftRunJson(const ModuleReport& m, const WatchedRowDrift& drift) {
  nlohmann::json j;
  j["counted"] = m.row_drift.read && drift.not_counted.empty();
  if (!drift.not_counted.empty()) j["not_counted"] = drift.not_counted;
  j["captures"] = drift.recent.captures;
  if (drift.recent.read) {
    j["mean_size_px"] = drift.recent.row_offset_px;
    j["standard_error_px"] = drift.recent.standard_error_px;
  }
  j["warned"] = drift.warned;
  j["warned_since"] = drift.warned_since;
  j["stays"] = drift.stays;
  if (drift.withdrawn_since != 0) j["withdrawn_since"] = drift.withdrawn_since;
  return j;
}

// Why a module's drift went unjudged (RowDriftWatch::Unjudged) and what to
// do, after "module M's row drift is not watched: ..." on stderr: in the
// words of a single capture's row-drift line where the matches reach an end.
std::string UnjudgedRowDriftAdvice() {
  return std::string(
             "its matches reaching an end of the measurement volume's disparity range at each capture "
             "(row_drift_run.not_counted: range_end_reached), where the grid can be matched a period off and the "
             "reading a vernier step; if the object is not well inside the volume, ") +
         kSetTheVolume + ", or check the part's position on the line (said once a run; the summary's " +
         "row_drift_unjudged_modules)";
}

// A module none of whose last readings counted: told once a run, on stderr
// (its captures' lines under each name the range end already), as soon as
// the watch has read the capture: a capture whose outputs then fail to be
// written must not take the run's only telling with it.
void SayRowDriftUnjudged(int module, const WatchedRowDrift& drift, const std::string& dir,
                         const std::string& progress) {
  if (!drift.unjudged) return;
  std::fprintf(stderr,
               "stereorig reconstruct: %s %s: warning: module %d's row drift is not watched: its last %d readings "
               "were not counted (%s), %s\n",
               progress.c_str(), PrintableText(dir).c_str(), module, drift.not_counted_in_a_row,
               drift.counted_before == 0 ? "none counted in this run"
                                         : (std::to_string(drift.counted_before) + " counted before them").c_str(),
               UnjudgedRowDriftAdvice().c_str());
}

// A module's rows read off over the run's recent captures: a line under the
// capture's on stdout at every capture it holds (the controller's answer),
// and on stderr, where a log keeps the problems, when it begins and when it
// is withdrawn (a warning may hold for days of captures: a line each would
// bury the log; the run's last stderr line counts the captures).
void SayRowDrift(int module, const WatchedRowDrift& drift, const std::string& dir, const CaptureOutputs& outputs,
                 const std::string& progress) {
  const int n = drift.recent.captures;
  const char* readings = n == 1 ? "'s" : "s'";
  const std::string not_counted =
      drift.not_counted.empty() ? "" : ", not counted: its matches reach an end of the volume's disparity range";
  if (drift.warned) {
    std::printf(
        "  warning: module %d's rectified rows read %.3f px off at the laser grid's vernier, the mean size of its "
        "last %d capture%s readings (standard error %.3f; this capture's in %s: row_drift%s); warned since this "
        "run's capture %d, %s: %s\n",
        module, drift.recent.row_offset_px, n, readings, drift.recent.standard_error_px,
        PrintableText(outputs.report).c_str(), not_counted.c_str(), drift.warned_since,
        drift.stays ? "and it stays for the run (given on a full window of readings): past ~0.2 px a module reads "
                      "small again, a whole grid period off"
                    : "on fewer readings than a full window (20): withdrawn if later ones bring the mean back",
        kRowDriftAdvice);
  }
  if (drift.started)
    std::fprintf(stderr,
                 "stereorig reconstruct: %s %s: warning: module %d's rectified rows read %.3f px off at the laser "
                 "grid's vernier (the mean size of its last %d capture%s readings, standard error %.3f): warned "
                 "under each capture from here while it holds; run `stereorig check` on the rig before trusting "
                 "that module's points\n",
                 progress.c_str(), PrintableText(dir).c_str(), module, drift.recent.row_offset_px, n, readings,
                 drift.recent.standard_error_px);
  if (drift.withdrawn_since != 0) {
    char mean[96] = "no reading counted";
    if (drift.recent.read)
      std::snprintf(mean, sizeof mean, "%.3f px (standard error %.3f)", drift.recent.row_offset_px,
                    drift.recent.standard_error_px);
    const std::string why = "module " + std::to_string(module) + "'s row-drift warning (since this run's capture " +
                            std::to_string(drift.withdrawn_since) + ") is withdrawn: the mean size of its last " +
                            std::to_string(n) + " capture" + readings + " readings is " + mean +
                            ", within tolerance; it rested on fewer readings than a full window (20), and one "
                            "capture can read a whole vernier step (0.36 px) off";
    std::printf("  note: %s (%s: row_drift_run)\n", why.c_str(), PrintableText(outputs.report).c_str());
    std::fprintf(stderr, "stereorig reconstruct: %s %s: note: %s\n", progress.c_str(), PrintableText(dir).c_str(),
                 why.c_str());
  }
}

}  // namespace

nlohmann::json ReconstructCapture(const Runtime& runtime, const std::vector<cv::Mat>& images, const std::string& dir,
                                  const std::string& name, const CaptureOutputs& outputs, const std::string& progress,
                                  std::chrono::steady_clock::time_point started, RowDriftWatch* row_drift) {
  const bool mesh = !outputs.mesh.empty();
  // The mesh's name may be an earlier run's cloud of a capture named like
  // it (`x.mesh` beside `x`, --mesh-format ply): replaced, another
  // capture's measurement was lost without a word.
  if (mesh && IsPlyCloudFile(outputs.mesh))
    throw InputError(outputs.mesh,
                     "is an earlier run's point cloud (of a capture named like this one's mesh): not replaced by this "
                     "capture's mesh; move it, or give another --out-dir");
  const Reconstruction rec = runtime.Process(images, mesh);
  const std::vector<WatchedRowDrift> recent_drift = row_drift->Add(rec.modules);
  for (size_t k = 0; k < rec.modules.size(); ++k)
    SayRowDriftUnjudged(rec.modules[k].module, recent_drift[k], dir, progress);
  // All or none: written beside their paths, then renamed in together, so a
  // failure (a full disk) or a signal while they are written leaves none of
  // them new beside an earlier run's others.
  AtomicOutputSet written;
  written.Add(outputs.cloud, EncodeCloudPly(rec.cloud));
  if (mesh) written.Add(outputs.mesh, EncodeMesh(rec.cloud, rec.mesh, outputs.mesh));
  nlohmann::json report = ReconstructionJson(rec);
  for (size_t k = 0; k < rec.modules.size(); ++k)
    report["modules"][k]["row_drift_run"] = RowDriftRunJson(rec.modules[k], recent_drift[k]);
  written.Add(outputs.report, JsonReportText(report) + "\n");
  written.Commit(outputs.at_existing);  // the report last: once it is there, so are the others
  // An earlier run's mesh of the other format would sit beside this cloud as
  // if it were its mesh; an earlier cloud of that name is another capture's.
  const std::vector<std::pair<std::string, std::string>> left = RemoveEarlierFiles(EarlierMeshes(outputs.earlier_only));
  nlohmann::json entry;
  entry["capture"] = dir;
  entry["name"] = name;
  entry["cloud"] = outputs.cloud;
  if (mesh) entry["mesh"] = outputs.mesh;
  entry["report"] = outputs.report;
  entry["ok"] = true;
  entry["points"] = rec.cloud.size();
  entry["point_cloud_ms"] = rec.times_ms.at("total_point_cloud");
  const double wall_ms = MsSince(started);
  entry["wall_ms"] = wall_ms;
  std::string fills;
  for (const ModuleReport& m : rec.modules) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%sm%d %.1f%%", fills.empty() ? "" : ", ", m.module, 100 * m.fill_rate());
    fills += buf;
  }
  // A stream's folder is a line of standard input: escaped as every error
  // line is (PrintableText).
  std::printf("%s %s: %zu points (fill %s), %.0f ms -> %s\n", progress.c_str(), PrintableText(dir).c_str(),
              rec.cloud.size(), fills.c_str(), wall_ms, PrintableText(outputs.cloud).c_str());
  for (const auto& [path, why] : left) {
    entry["left_behind"].push_back(path);
    std::printf("  warning: %s (an earlier run's) could not be removed: %s\n", PrintableText(path).c_str(),
                why.c_str());
    std::fprintf(stderr, "stereorig reconstruct: %s %s: warning: %s (an earlier run's) could not be removed: %s\n",
                 progress.c_str(), PrintableText(dir).c_str(), PrintableText(path).c_str(), why.c_str());
  }
  // The one-capture summary's warning (module_summary.h), in a line per
  // module: a batch or a stream is what a line runs.
  entry["modules_with_row_drift"] = nlohmann::json::array();
  for (size_t k = 0; k < rec.modules.size(); ++k) {
    const ModuleReport& m = rec.modules[k];
    const std::string which = RangeEndsWarnedOf(m);
    if (!which.empty())
      std::printf(
          "  warning: module %d's matches reach %s of the measurement volume's disparity range (%s: "
          "range_end_reached): its points may lie where nothing is; check the volume\n",
          m.module, which.c_str(), outputs.report.c_str());
    if (recent_drift[k].warned) entry["modules_with_row_drift"].push_back(m.module);
    SayRowDrift(m.module, recent_drift[k], dir, outputs, progress);
  }
  entry["modules_without_points"] =
      WarnOfModulesWithoutPoints(rec, IsPassive(runtime.options()), dir, outputs, progress);
  FlushStdout();
  return entry;
}

nlohmann::json FailedCapture(const std::string& dir, const std::string& name, const CaptureOutputs& outputs,
                             const std::string& progress, const std::string& why) {
  // An earlier run's files of this name removed first (a batch's: it
  // replaces them), so that the lines below are true when printed; one that
  // cannot be removed is named in them and in the entry, not passed over.
  // Not the mesh's name where it holds an earlier run's cloud of another
  // capture (ReconstructCapture refuses to replace it).
  std::vector<std::string> paths = {outputs.cloud, outputs.report,
                                    IsPlyCloudFile(outputs.mesh) ? std::string() : outputs.mesh};
  const std::vector<std::string> meshes = EarlierMeshes(outputs.earlier_only);
  paths.insert(paths.end(), meshes.begin(), meshes.end());
  std::string left_behind;
  nlohmann::json left = nlohmann::json::array();
  for (const auto& [path, why] : RemoveEarlierFiles(paths)) {
    left_behind += "; " + path + " (an earlier output) could not be removed: " + why;
    left.push_back(path);
  }
  std::fprintf(stderr, "stereorig reconstruct: %s %s%s\n", progress.c_str(), PrintableText(why).c_str(),
               PrintableText(left_behind).c_str());
  // On stdout too, once the capture's files are as they stay: a caller
  // reading each capture's line there (a batch's or a stream's) gets one for
  // every capture, not only for those written, and acts on it at once.
  std::printf("%s %s: no output (%s%s)\n", progress.c_str(), PrintableText(dir).c_str(), PrintableText(why).c_str(),
              PrintableText(left_behind).c_str());
  FlushStdout();
  nlohmann::json entry;
  entry["capture"] = dir;
  entry["name"] = name;
  entry["ok"] = false;
  entry["error"] = why;
  if (!left.empty()) entry["left_behind"] = left;
  return entry;
}

int FinishRun(nlohmann::json* summary, int total, int failed, int without_points, int with_row_drift,
              const RowDriftWatch& row_drift, double wall_ms, const std::string& timed,
              const std::string& summary_path) {
  const int done = total - failed;
  (*summary)["reconstructed"] = done;
  (*summary)["failed"] = failed;
  (*summary)["with_modules_without_points"] = without_points;
  (*summary)["with_row_drift"] = with_row_drift;
  const std::vector<UnjudgedRowDrift> unjudged = row_drift.Unjudged();
  (*summary)["row_drift_unjudged_modules"] = nlohmann::json::array();
  for (const UnjudgedRowDrift& u : unjudged) (*summary)["row_drift_unjudged_modules"].push_back(u.module);
  (*summary)["wall_ms"] = wall_ms;
  (*summary)["objects_per_s"] = done > 0 ? 1000.0 * done / wall_ms : 0.0;
  std::printf("%d of %d captures in %.2f s: %.1f objects/s (%s)", done, total, wall_ms / 1000,
              (*summary)["objects_per_s"].get<double>(), timed.c_str());
  if (without_points > 0) std::printf("; %d with a module that gave no point", without_points);
  if (with_row_drift > 0) std::printf("; %d with a module whose rows read off (row_drift)", with_row_drift);
  std::printf("\n");
  FlushStdout();
  if (without_points > 0)
    std::fprintf(stderr,
                 "stereorig reconstruct: warning: %d of %d captures written have a module that gave no point (each "
                 "named above, with why)\n",
                 without_points, done);
  if (with_row_drift > 0)
    std::fprintf(stderr,
                 "stereorig reconstruct: warning: %d of %d captures written have a module whose rectified rows read "
                 "off (each named above): run `stereorig check` on the rig before trusting that module's points\n",
                 with_row_drift, done);
  // A run too short for a module's uncounted readings to fill a window
  // (RowDriftWatch) still tells one none of whose readings counted.
  for (const UnjudgedRowDrift& u : unjudged)
    if (u.unjudged_since == 0)
      std::fprintf(stderr,
                   "stereorig reconstruct: warning: module %d's row drift was not watched in this run: none of its %d "
                   "reading%s was counted, %s\n",
                   u.module, u.not_counted, u.not_counted == 1 ? "" : "s", UnjudgedRowDriftAdvice().c_str());
  // Stdout lost on the last lines (a terminal's hang-up): the summary says
  // so, as for a capture's line, and main exits 2 (cli_util.h).
  const std::string lost = StdoutWriteError();
  if (!lost.empty() && !summary->contains("output_error")) (*summary)["output_error"] = lost;
  if (!summary_path.empty()) WriteFileAtomically(summary_path, JsonReportText(*summary) + "\n");
  if (failed == 0) return kExitOk;
  std::fprintf(stderr,
               "stereorig reconstruct: %d of %d captures failed (bad input, or outputs that could not be "
               "written) and have no output\n",
               failed, total);
  return kExitBadInput;
}

}  // namespace stereorig
