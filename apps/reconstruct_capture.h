// One capture of a many-capture run of `stereorig reconstruct` (a batch,
// reconstruct_batch.h, or a stream, reconstruct_stream.h): reconstructed by
// the run's runtime, its outputs written, its line printed. Shared so that a
// batch and a stream write, say and record the same for a capture.
#pragma once

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "apps/row_drift_watch.h"
#include "calib/core/atomic_file.h"
#include "calib/core/rig.h"
#include "reconstruct/runtime.h"

namespace stereorig {

// Every file one capture writes: its cloud, its report, its mesh ("" if none).
struct CaptureOutputs {
  std::string cloud, report, mesh;
  // A batch's replace an earlier run's files; a stream's never replace a
  // file, one made after the stream's check that the names were free
  // included (atomic_file.h AtExisting: the capture is then refused).
  AtExisting at_existing = AtExisting::kReplace;
  // Files of the capture's name an earlier run may have left that this run
  // does not write (AddEarlierMeshes), removed with the capture's outputs,
  // written or failed, so that none is taken for this run's: a batch's. One
  // that is a PLY cloud (ply_cloud_file.h) is another capture's cloud (an
  // earlier run's folder "x.mesh"), not a mesh, and is left.
  std::vector<std::string> earlier_only{};
};

// The outputs of the capture named `name` in `out_dir`: <name>.ply,
// <name>.json and, unless mesh_format is "", <name>.mesh.<mesh_format>.
CaptureOutputs CaptureOutputsNamed(const std::string& out_dir, const std::string& name, const std::string& mesh_format);

// Sets each capture's earlier_only to the meshes an earlier run may have
// written for its name (outputs[i].cloud's, in out_dir) that a run of
// `mesh_format` does not: <name>.mesh.stl with ply, <name>.mesh.ply with
// stl, both with "" (no mesh); but none that is a file this run writes (one
// of `outputs`: folders "x" and "x.mesh" without --mesh-format, x.mesh.ply
// is a cloud) or one of `also` (its inputs and summary; "" ignored). A batch's.
void AddEarlierMeshes(const std::string& out_dir, const std::string& mesh_format, const std::vector<std::string>& also,
                      std::vector<CaptureOutputs>* outputs);

// The folder `dir` as the file system finds it (NormalPath,
// calib/core/folder_to_create.h: absolute, links followed; a part that does
// not exist or cannot be looked up, such as a link loop, kept as written
// below the part that resolves), no trailing separator. A
// batch's "given twice" and a stream's --capture-root compare folders so, not
// their paths' text ("nm/q" and "link_to_nm/q" are one folder).
std::filesystem::path ResolvedFolder(const std::string& dir);

// LoadCapture (runtime.h), any failure as bad input naming the folder: a
// folder removed or made unreadable after its files were checked throws a
// std::filesystem error, here an InputError.
std::vector<cv::Mat> LoadCaptureOrInputError(const std::string& dir, const Rig& rig);

// Reconstructs the capture from folder `dir` (its decoded `images`),
// writes its outputs, all or none (atomic_file.h AtomicOutputSet, as
// outputs.at_existing says; the mesh only if outputs.mesh is set), then
// removes the files of outputs.earlier_only that are meshes (not a PLY
// cloud: another capture's, ply_cloud_file.h). The report's modules each get
// `row_drift_run`, the run's verdict at this capture (RowDriftWatch: counted,
// not_counted, captures, mean_size_px, standard_error_px, warned,
// warned_since, stays, withdrawn_since). Prints to stdout, flushed,
// "<progress> <dir>: N points (fill m0 x%, m1 y%), T ms -> <cloud>" (T: the
// wall time since `started`, when the capture's turn began: waiting for its
// images, reconstructing, writing), then a line per earlier_only file that
// could not be removed ("  warning: <path> (an earlier run's) could not be
// removed: <why>", also on stderr; the entry's left_behind), then a warning
// line per module whose matches reach an end of the volume's disparity
// range (module_summary.h RangeEndsWarnedOf), one per module whose rows read
// off over the run's recent captures (`row_drift`: the mean of its last
// sound readings, RowDriftWatch, to which this capture's are added; on
// stderr too when the warning begins, and a note on both when it is
// withdrawn; on stderr once a run, "module M's row drift is not watched",
// where its readings have gone a window, RowDriftWatch::kCaptures, in a row
// not counted for a range end), and one per module that gave
// no point ("  warning: module M gave no point (<report>): <why>",
// module_summary.h NoPointReason; also on stderr, "stereorig reconstruct:
// <progress> <dir>: warning: ..."). Returns the capture's entry of the run's
// summary (capture, name, ok, cloud, mesh, report, points, point_cloud_ms,
// wall_ms, modules_without_points, modules_with_row_drift). Throws InputError if an output cannot be written
// (the writers', atomic_file.h); the caller then calls FailedCapture.
nlohmann::json ReconstructCapture(const Runtime& runtime, const std::vector<cv::Mat>& images, const std::string& dir,
                                  const std::string& name, const CaptureOutputs& outputs, const std::string& progress,
                                  std::chrono::steady_clock::time_point started, RowDriftWatch* row_drift);

// A capture that failed (bad images, outputs that could not be written, a
// name already used): it has no output, not a partial one nor a stale one
// from an earlier run (every file of `outputs` that exists is removed, its
// earlier_only's meshes too: a batch's; a stream, which never replaces a file,
// passes none),
// "stereorig reconstruct: <progress> <why>" goes to stderr and
// "<progress> <dir>: no output (<why>)" to stdout, flushed. Returns its entry
// of the summary (capture, name, ok false, error).
nlohmann::json FailedCapture(const std::string& dir, const std::string& name, const CaptureOutputs& outputs,
                             const std::string& progress, const std::string& why);

// The run's end: "<done> of <total> captures in S s: R objects/s (<timed>)"
// on stdout (`timed`: what the wall time holds), followed by "; K with a
// module that gave no point" when `without_points` (of the captures written)
// is not 0, and "; K with a module whose rows read off (row_drift)" when
// `with_row_drift` is not 0 (captures whose entry lists
// modules_with_row_drift); the summary's totals (reconstructed, failed,
// with_modules_without_points, with_row_drift, wall_ms, objects_per_s) set,
// with row_drift_unjudged_modules (the run's RowDriftWatch::Unjudged: the
// modules whose drift went unjudged, their readings not counted, told on
// stderr at the capture that made a window of them, or here, for a module
// none of whose readings counted in a shorter run) and the summary
// written atomically to summary_path (unless ""); with failures, or captures
// with a module that gave no point or whose rows read off, a stderr line
// that counts them. Returns
// the exit code: kExitOk, or kExitBadInput when any capture failed. A module
// with no point does not change it: the capture was measured and written, and
// 1 is a check's failure (docs/formats.md); the count is the controller's.
int FinishRun(nlohmann::json* summary, int total, int failed, int without_points, int with_row_drift,
              const RowDriftWatch& row_drift, double wall_ms, const std::string& timed,
              const std::string& summary_path);

}  // namespace stereorig
