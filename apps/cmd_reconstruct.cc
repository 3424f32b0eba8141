// `stereorig reconstruct`: rig file + capture -> point cloud, mesh, report.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/module_summary.h"
#include "apps/output_paths.h"
#include "apps/reconstruct_batch.h"
#include "apps/reconstruct_json.h"
#include "apps/reconstruct_stream.h"
#include "apps/rectified_pairs.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "calib/json_text.h"
#include "reconstruct/ply_io.h"
#include "reconstruct/runtime.h"

namespace stereorig {

namespace {

// Hole filling runs on the joined mesh: with shape_model set and no mesh
// asked for, nothing is filled, which the run did without a word.
void NoteShapeModelWithoutMesh(const RuntimeOptions& options, bool mesh) {
  if (options.shape_model == ShapeModel::kNone || mesh) return;
  std::printf(
      "note: shape_model %s fills holes only with a mesh (--mesh; --mesh-format for many captures): nothing will "
      "be filled\n",
      ShapeModelName(options.shape_model));
  FlushStdout();
}

}  // namespace

int RunReconstruct(int argc, char** argv) {
  CLI::App app{
      "One capture in, a measured 3D model out: rectify each module, match (census SGM tuned to the laser grid, "
      "filters, sub-pixel), triangulate to mm, merge all modules through S into the reference frame (module 0), "
      "normals; optionally an organised mesh per module, joined, with holes closed by a fitted shape model.\n"
      "The capture folder holds camK.png (8-bit grey) for every camera K of the rig. Runtime options (YAML) "
      "give the measurement volume and object size; docs/reconstruct.md lists every key. The defaults are for "
      "captures under the laser grids; a capture without them (passive) needs crop_to_lit_region: false and "
      "match: {min_distinctness: 0, grid_line_test: false, line_index: false} (`stereorig demo` writes such a file, "
      "passive_options.yaml).\n"
      "In the line, give many captures and --out-dir: one process (starting one costs ~0.25 s: loading the "
      "libraries, reading the rig, building the rectification maps) reconstructs them all, the next capture "
      "read while one is reconstructed, and each capture writes <name>.ply and <name>.json (and "
      "<name>.mesh.ply|stl with --mesh-format), <name> being its folder's path after the part all share "
      "('caps/0001' -> 0001, 'scenes/cup/active' and 'scenes/sphere/active' -> cup_active, sphere_active). "
      "Missing or extra camK.png files, or clashing output names, stop the batch before anything is written; a "
      "capture whose images cannot be decoded or have the wrong size is reported and gets no output, the others "
      "go on, and the exit code is 2.\n"
      "Driven by the line's acquisition software, one capture at a time: --capture - reads the capture folders "
      "from standard input, one path per line, sent once the folder is complete (a pipe, or a FIFO: see "
      "docs/reconstruct.md, 'Captures as they come'), and reconstructs each as its line arrives, with one runtime "
      "built at the start; each capture writes <name>.ply and <name>.json, <name> its folder's last name, and "
      "prints one line on stdout at once, before it reads the next folder: '[k] DIR: N points (fill m0 x%, m1 y%), T "
      "ms -> OUT/<name>.ply' or '[k] DIR: no output (<why>)' (lines after it that start with two spaces are "
      "warnings). An output that exists is never replaced. A bad capture (a missing camera, bad images, an output name "
      "that exists already) is named on stderr and on its line, gets no "
      "output, and the stream goes on; the end of the input ends the run (exit 2 if any capture failed), and so "
      "does SIGTERM, SIGHUP or Ctrl-C, once the capture in progress is written (exit as at the end; its summary "
      "says so), and so does a stdout that cannot be written (a reader gone: exit 2). A batch or a single capture "
      "dies of those signals at once, leaving no partial file.\n\n"
      "Exit codes: 0 ok (a module that gave no point or whose rows read off too: warned of on stderr); 2 bad usage or "
      "input, or a capture "
      "of a batch or stream that failed (it has no output; the others' outputs are written).\n\n"
      "Examples:\n  stereorig reconstruct --rig rig.yaml --capture data/scenes/cup/active --out cup.ply "
      "--mesh cup.stl --report cup.json\n"
      "  stereorig reconstruct --rig rig.yaml --capture line/0001 line/0002 line/0003 --out-dir clouds "
      "--report clouds/batch.json\n"
      "  acquire | stereorig reconstruct --rig rig.yaml --capture - --out-dir clouds   (acquire prints each "
      "complete capture folder's path)",
      "stereorig reconstruct"};
  std::vector<std::string> capture_dirs;
  std::string rig_path, out_path, out_dir, mesh_path, mesh_format, report_path, options_path;
  app.add_option("--rig", rig_path, "rig file (from stereorig calibrate)")->required();
  app.add_option(
         "--capture", capture_dirs,
         "capture folder(s) with camK.png per camera; several (or repeated) need --out-dir; '-' reads them from "
         "standard input, one per line, as they come")
      ->required();
  auto* out = app.add_option("--out", out_path, "one capture: the point cloud (binary PLY)")->check(NonEmptyPath());
  auto* dir =
      app.add_option("--out-dir", out_dir, "many captures: write <name>.ply, <name>.json here")->check(NonEmptyPath());
  auto* mesh = app.add_option("--mesh", mesh_path, "one capture: also write the joined mesh (.ply or .stl)")
                   ->check(NonEmptyPath());
  auto* format = app.add_option("--mesh-format", mesh_format, "many captures: also write <name>.mesh.<ply|stl>");
  app.add_option("--report", report_path,
                 "one capture: its per-step times, point counts and fill rates as JSON; many: the batch's summary; "
                 "--capture -: the stream's totals and failed captures, written when the input ends or a stop signal "
                 "(SIGTERM, SIGHUP, Ctrl-C) ends the stream, once a capture has come")
      ->check(NonEmptyPath());
  app.add_option("--options", options_path, "runtime options YAML (default: the built-in defaults)");
  std::string warm_up_dir, capture_root, rectified_dir;
  auto* rectified =
      app.add_option(
             "--rectified-out", rectified_dir,
             "one capture: also write each module's rectified pair here (moduleM_left.png, moduleM_right.png, created "
             "if needed) and print the `stereorig match` command that searches it with the range and ROI the runtime "
             "derives from the measurement volume (before its lit-region crop and band pass)")
          ->check(NonEmptyPath());
  app.add_option("--capture-root", capture_root,
                 "with --capture -: name each capture by its folder's path below this folder, joined with '_' "
                 "(root line: line/2026-12-06/0001 -> 2026-12-06_0001) instead of its last name; folders not below "
                 "it are refused");
  app.add_option("--warm-up", warm_up_dir,
                 "with --capture -: reconstruct this capture once before reading the first folder, writing "
                 "nothing, so that the line's first object does not pay the first capture's start-up costs (a "
                 "capture of a typical object)");
  out->excludes(dir);
  mesh->excludes(dir);
  rectified->excludes(dir);
  format->needs(dir);
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  // In any case, as --mesh's suffix (STL, Ply): the files are named in lower case.
  for (char& c : mesh_format) c = char(std::tolower(static_cast<unsigned char>(c)));
  const bool stream = std::find(capture_dirs.begin(), capture_dirs.end(), "-") != capture_dirs.end();
  if (stream && capture_dirs.size() > 1)
    throw InputError("--capture", "'-' (the capture folders read from standard input) must be the only --capture");
  if (app.count("--capture-root") > 0 && !stream)
    throw InputError("--capture-root",
                     "is for a stream of captures (--capture -): a batch names its captures after "
                     "the folders they all share");
  if (!warm_up_dir.empty() && !stream)
    throw InputError("--warm-up",
                     "is for a stream of captures (--capture -): a batch or one capture has no first "
                     "object to wait for it");
  if (stream && out_dir.empty())
    throw InputError("--capture", "'-' (the capture folders read from standard input) needs --out-dir DIR");
  if (out_dir.empty() && out_path.empty())
    throw InputError("--out", "give --out (one capture) or --out-dir (many captures)");
  if (out_dir.empty() && capture_dirs.size() > 1)
    throw InputError("--capture",
                     std::to_string(capture_dirs.size()) + " captures given: write them with --out-dir DIR, not --out");
  if (!out_dir.empty()) {
    // The batch checks its own outputs (reconstruct_batch.h); here only that
    // its summary is not over an input (its folder may be the one it creates).
    if (!report_path.empty())
      ClaimRuntimeReport(
          {.path = report_path, .rig_path = rig_path, .options_path = options_path, .check_folder = false});
    const Rig rig = ReadRigFile(rig_path);
    const RuntimeOptions options = options_path.empty() ? RuntimeOptions{} : ReadRuntimeOptions(options_path);
    NoteShapeModelWithoutMesh(options, !mesh_format.empty());
    if (stream)
      return ReconstructStream(
          rig, options,
          StreamRequest{out_dir, mesh_format, report_path, rig_path, options_path, warm_up_dir, capture_root},
          STDIN_FILENO);
    return ReconstructBatch(rig, options,
                            BatchRequest{capture_dirs, out_dir, mesh_format, report_path, rig_path, options_path});
  }
  const std::string& capture_dir = capture_dirs.front();

  // Every input, and where each output goes, is checked before any work.
  // The rig file is read first: it says which capture images will be read,
  // and none of them may be an output (--out DIR/cam0.png).
  const Rig rig = ReadRigFile(rig_path);
  OutputPaths outputs;
  ProtectCaptureInputs(rig_path, options_path, capture_dir, rig, &outputs);
  // The folder --rectified-out creates first: the cloud, mesh or report may
  // go in it (--rectified-out r --out r/x.ply was refused as "its folder
  // does not exist", r being the folder the run makes).
  FolderToCreate rectified_folder;  // made once the capture is reconstructed
  std::vector<RectifiedPairPaths> rectified_paths;
  if (!rectified_dir.empty()) {
    rectified_folder = outputs.ClaimFolder(rectified_dir, "the rectified pairs (--rectified-out)");
    rectified_paths = RectifiedPairPathsIn(rectified_dir, rig.num_modules());
    for (const RectifiedPairPaths& pair : rectified_paths) {
      outputs.Claim(pair.left, "a rectified left image (--rectified-out)", false);
      outputs.Claim(pair.right, "a rectified right image (--rectified-out)", false);
    }
  }
  auto claim = [&](const std::string& path, const std::string& what) {
    namespace fs = std::filesystem;
    outputs.Claim(path, what, !rectified_folder.WillCreate(fs::absolute(path).parent_path()));
  };
  claim(out_path, "the cloud (--out)");
  CheckCloudPath(out_path);  // after the claim: "is an input" says more than "not .ply" would
  if (!mesh_path.empty()) {
    CheckMeshPath(mesh_path);
    claim(mesh_path, "the mesh (--mesh)");
  }
  if (!report_path.empty()) claim(report_path, "the report (--report)");
  const RuntimeOptions options = options_path.empty() ? RuntimeOptions{} : ReadRuntimeOptions(options_path);
  NoteShapeModelWithoutMesh(options, !mesh_path.empty());
  const std::vector<cv::Mat> images = LoadCapture(capture_dir, rig);
  const Runtime runtime(rig, options);
  const Reconstruction rec = runtime.Process(images, !mesh_path.empty());

  // Before any output is staged: the cloud's temporary file may go in it.
  rectified_folder.Create();
  // All or none: a report that cannot be written (a full disk) leaves an
  // earlier run's cloud and mesh as they were, not a new cloud beside them.
  // Declared after `rectified_folder`: its temporary files go before the
  // folder made for them, which is removed while empty if the run fails.
  AtomicOutputSet written;
  written.Add(out_path, EncodeCloudPly(rec.cloud));
  if (!mesh_path.empty()) written.Add(mesh_path, EncodeMesh(rec.cloud, rec.mesh, mesh_path));
  if (!report_path.empty()) written.Add(report_path, JsonReportText(ReconstructionJson(rec)) + "\n");
  if (!rectified_paths.empty()) AddRectifiedPairs(runtime, images, rectified_paths, &written);
  written.Commit();
  for (const ModuleReport& m : rec.modules)
    std::printf("%s\n",
                ModuleSummary(m, {.passive = IsPassive(options), .say_whose = &m == &rec.modules.front()}).c_str());
  // On stderr too: a script that keeps only stderr, or a log, must not take
  // a module that measured nothing (lasers off, a camera not triggered) for
  // a measurement; the exit code stays 0 (the capture was reconstructed).
  for (const ModuleReport& m : rec.modules)
    if (const std::string why = NoPointReason(m, IsPassive(options)); !why.empty())
      std::fprintf(stderr, "stereorig reconstruct: warning: module %d gave no point: %s\n", m.module, why.c_str());
  // So is a module whose rows read off: its points may be a grid period off
  // while the fill looks right (docs/reconstruct.md, "Row drift").
  // A module whose matches reach an end of the range may read a whole
  // vernier step off whatever its rows are (row_drift_watch.h, which leaves
  // such readings out): the volume first, then the rig.
  for (const ModuleReport& m : rec.modules) {
    if (!m.row_drift.warned) continue;
    const std::string ends = RangeEndsWarnedOf(m);
    std::fprintf(stderr,
                 "stereorig reconstruct: warning: module %d's rectified rows read %+.3f px off at the laser grid's "
                 "vernier (standard error %.3f; its summary above): %s\n",
                 m.module, m.row_drift.row_offset_px, m.row_drift.standard_error_px,
                 ends.empty() ? "run `stereorig check` on the rig before trusting that module's points"
                              : ("its matches reach " + ends +
                                 " of the range, where the grid can be matched a period off and the reading a vernier "
                                 "step: check the volume first, then run `stereorig check` on the rig")
                                    .c_str());
  }
  std::printf("%zu points (%d from the shape model) in %.1f ms; wrote %s", rec.cloud.size(), rec.filled_points,
              rec.times_ms.at("total_point_cloud"), out_path.c_str());
  if (!mesh_path.empty()) std::printf(", %s (%zu triangles)", mesh_path.c_str(), rec.mesh.triangles.size());
  if (!report_path.empty()) std::printf(", %s", report_path.c_str());
  std::printf("\n");
  if (!mesh_path.empty()) std::printf("shape model: %s\n", rec.shape_fit.c_str());
  for (size_t m = 0; m < rectified_paths.size(); ++m)
    std::printf("%s\n", RectifiedPairLine(runtime.plans()[m], rectified_paths[m]).c_str());
  return kExitOk;
}

}  // namespace stereorig
