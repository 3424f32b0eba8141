// `stereorig check`: the nightly recalibration check. Fresh target captures
// + the stored rig file -> ok / recalibrate / recapture, what moved, and history.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "calib/capture_folder.h"
#include "calib/check/board_pose.h"
#include "calib/check/check_target.h"
#include "calib/check/history.h"
#include "calib/check/nightly_check.h"
#include "calib/core/atomic_file.h"
#include "calib/core/capture_image_name.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/number_text.h"
#include "calib/core/rig_file.h"
#include "calib/json_text.h"
#include "targets/target_file.h"

#include <zlib.h>

namespace stereorig {

namespace {

std::string DefaultHistoryPath(const std::string& rig_path) {
  return (std::filesystem::path(rig_path).parent_path() / "check-history.sqlite").string();
}

// A camK.png with K beyond the rig's cameras (in a capture folder, or a
// dataset's calibration/NNN/) means the captures come from a larger rig.
void RejectCamerasBeyondTheRig(const std::string& captures, int num_cameras) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(captures)) return;  // the detector names a missing folder
  for (auto it = fs::recursive_directory_iterator(captures); it != fs::recursive_directory_iterator(); ++it) {
    if (it.depth() >= 2) it.disable_recursion_pending();
    const std::optional<int> camera = CameraIndexOfImageName(it->path().filename().string());
    if (camera && *camera >= num_cameras) {
      // The rig's cameras are numbered from 0: "camera 4, but the rig has 4
      // cameras" read as a contradiction.
      throw InputError(it->path().string(),
                       (*camera == kCameraIndexBeyondAnyRig ? std::string("a camera index beyond any rig")
                                                            : "camera " + std::to_string(*camera)) +
                           ", but the rig has " + std::to_string(num_cameras) + " cameras, cam0.png" +
                           (num_cameras > 1 ? " to cam" + std::to_string(num_cameras - 1) + ".png" : "") +
                           " (numbered from 0): captures from another rig?");
    }
  }
}

// The CRC-32 of the rig file's bytes as 8 hex digits (zlib's): what tells
// the rig file a night used from another written to the same path. Not a
// guard against tampering, only a fingerprint. Of the bytes the rig was
// parsed from (ReadRigFile's, one read): a second read a moment later took
// the fingerprint of a file replaced in between, and of a pipe none.
uLong Crc32Update(uLong crc, const char* bytes, size_t size) {
  for (size_t done = 0; done < size;) {  // uInt lengths: in pieces
    const size_t piece = std::min<size_t>(size - done, 1u << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes + done), static_cast<uInt>(piece));
    done += piece;
  }
  return crc;
}

std::string Crc32Text(uLong crc) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "%08lx", static_cast<unsigned long>(crc));
  return hex;
}

std::string Crc32Hex(const std::string& bytes) {
  return Crc32Text(Crc32Update(crc32(0L, Z_NULL, 0), bytes.data(), bytes.size()));
}

// A CRC-32 of the capture images, each one's name within its capture
// ("000/cam0.png") and its bytes, in CaptureFolderImages' order: the same
// night checked again (or a copy of it elsewhere) reads as the same, an
// image taken again as another night. What the history tells a night
// appended twice by. An image that cannot be read, or is no regular file (a
// pipe, a link to /dev/zero: opened here, it blocked or never ended), counts
// by its name (the detection refuses it).
std::string CapturesCrc32Hex(const std::string& captures) {
  namespace fs = std::filesystem;
  uLong crc = crc32(0L, Z_NULL, 0);
  std::vector<char> buffer(1 << 20);
  for (const std::string& image : CaptureFolderImages(captures)) {
    const fs::path path(image);
    const std::string name = (path.parent_path().filename() / path.filename()).string();
    crc = Crc32Update(crc, name.c_str(), name.size() + 1);  // with its '\0': names and bytes do not run together
    std::error_code error;
    if (!fs::is_regular_file(path, error)) continue;
    std::ifstream in(image, std::ios::binary);
    while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0)
      crc = Crc32Update(crc, buffer.data(), size_t(in.gcount()));
  }
  return Crc32Text(crc);
}

// RunNightlyCheck, and where the captures fit the rig not at all, whether
// they fit it with the cameras' images exchanged: a module's cables swapped
// with another's (cam0<->cam2, cam1<->cam3) or cameras rotated three ways
// read "captures of another rig, or the wrong rig file or target file?",
// while the detection showed each module seeing the other's face of the
// board. On that refusal only, the exchanges of the cameras' images (up to 4
// cameras: 23; more are not tried) that leave each module's two cameras on
// one face of the board in every capture both see it are ranked by how well
// each capture then fits one board pose, the best two checked, and one under
// which every figure is within its threshold named instead of the guess. SwappedCameras (nightly_check.cc) names two
// cameras exchanged before this.
CheckResult RunCheckNamingExchangedImages(const Rig& rig, const Target& target, const DetectedCaptures& detected,
                                          const CheckOptions& options, const std::string& captures) {
  try {
    return RunNightlyCheck(rig, target, detected.observations, options, captures, detected.capture_names);
  } catch (const InputError& e) {
    const int n = rig.num_cameras();
    const size_t guess = e.problem().find(": captures of another rig");
    if (e.problem().rfind("the captures do not fit this rig at all", 0) != 0 || guess == std::string::npos || n > 4)
      throw;
    std::map<std::pair<int, int>, Face> face;  // (capture, camera) -> the face it saw
    std::vector<int> fronts(n, 0), backs(n, 0);
    for (const BoardObservation& v : detected.observations) {
      face[{v.capture, v.camera}] = v.face;
      ++(v.face == Face::kFront ? fronts : backs)[v.camera];
    }
    std::vector<int> module_of(n, -1);
    for (int m = 0; m < rig.num_modules(); ++m)
      module_of[rig.module(m).left_camera] = module_of[rig.module(m).right_camera] = m;
    // The exchanges in order of how well each capture's views, so
    // exchanged, fit one board pose (the median of the captures' RMS): only
    // the best two are checked whole.
    std::vector<std::pair<double, std::vector<int>>> candidates;
    std::vector<int> as(n);  // camera c's images are camera as[c]'s
    for (int c = 0; c < n; ++c) as[c] = c;
    while (std::next_permutation(as.begin(), as.end())) {
      bool one_face = true;  // each module's two cameras, as exchanged, on one face
      // Over the captures' own indices: folder numbers (100..107), not 0..N-1.
      for (int a = 0; a < n && one_face; ++a)
        for (int b = 0; b < n && one_face; ++b)
          for (auto it = face.begin(); a != b && it != face.end() && one_face; ++it) {
            const int capture = it->first.first;
            if (it->first.second == a && module_of[as[a]] == module_of[as[b]] && face.count({capture, b}))
              one_face = it->second == face.at({capture, b});
          }
      if (!one_face) continue;
      std::vector<BoardObservation> views = detected.observations;
      for (BoardObservation& v : views) v.camera = as[v.camera];
      std::map<int, std::vector<const BoardObservation*>> by_capture;
      for (const BoardObservation& v : views) by_capture[v.capture].push_back(&v);
      std::vector<double> rms_px;
      for (const auto& [capture, vs] : by_capture) {
        if (vs.size() < 2) continue;
        const BoardPoseEstimate pose = EstimateBoardPose(rig, target, vs);
        rms_px.push_back(pose.ok ? pose.rms_px : 1e9);
      }
      if (rms_px.empty()) continue;
      std::nth_element(rms_px.begin(), rms_px.begin() + rms_px.size() / 2, rms_px.end());
      candidates.push_back({rms_px[rms_px.size() / 2], as});
    }
    std::sort(candidates.begin(), candidates.end());
    for (size_t k = 0; k < std::min<size_t>(candidates.size(), 2); ++k) {
      as = candidates[k].second;
      std::vector<BoardObservation> views = detected.observations;
      for (BoardObservation& v : views) v.camera = as[v.camera];
      try {
        // The verdict, not the figures alone: images read through the wrong
        // lenses can raise tonight's noise, and every threshold with it.
        if (RunNightlyCheck(rig, target, views, options, captures, detected.capture_names).Verdict() != "ok") continue;
      } catch (const InputError&) {
        continue;
      }
      std::string exchanged, seen;
      for (int c = 0; c < n; ++c) {
        if (as[c] != c)
          exchanged += (exchanged.empty() ? "" : ", ") + CameraImageName(c) + " is cam" + std::to_string(as[c]) + "'s";
        if (fronts[c] + backs[c] > 0)
          seen += (seen.empty() ? "cam" : ", cam") + std::to_string(c) + (fronts[c] >= backs[c] ? " front" : " back");
      }
      throw InputError(e.where(), e.problem().substr(0, guess) + ", but with the cameras' images exchanged (" +
                                      exchanged +
                                      ") every figure is within its threshold: cables or image folders mixed up? "
                                      "(the faces of the board seen: " +
                                      seen + ")");
    }
    throw;
  }
}

// The runs --history lists one a line: a month of nights.
constexpr size_t kHistoryRunsListed = 31;

// --history --json: every run with its inputs, its figures and the views it
// set aside, for a line controller or a plot; a text kept empty ("" where a
// run from before did not keep it) reads null.
int PrintHistoryJson(const std::string& db) {
  const auto runs = ReadHistoryRuns(db);
  const HistorySetAsideLog set_aside = ReadHistorySetAside(db);
  std::map<long long, nlohmann::json> figures, views;
  for (const FigureTrend& t : ReadHistoryTrends(db))
    for (const HistoryPoint& p : t.points)
      figures[p.run_id][t.name] = {{"value", p.value}, {"threshold", p.threshold}, {"pass", p.pass}};
  for (const HistorySetAside& v : set_aside.views)
    views[v.run_id].push_back({{"capture", v.capture},
                               {"camera", v.camera},
                               {"jump_rms_px", v.jump_rms_px},
                               {"bound_px", v.bound_px},
                               {"tilt_deg", v.tilt_deg ? nlohmann::json(*v.tilt_deg) : nlohmann::json()}});
  auto text = [](const std::string& t) { return t.empty() ? nlohmann::json() : nlohmann::json(t); };
  nlohmann::json out = {{"db", db}, {"runs", nlohmann::json::array()}};
  for (const HistoryRun& r : runs) {
    const bool views_kept = set_aside.since_run_id > 0 && r.id >= set_aside.since_run_id;
    out["runs"].push_back({{"id", r.id},
                           {"date_utc", r.date_utc},
                           {"verdict", r.verdict},
                           {"explanation", r.explanation},
                           {"k_sigma", r.k_sigma ? nlohmann::json(*r.k_sigma) : nlohmann::json()},
                           {"rig_file", r.rig_file},
                           {"rig_crc32", text(r.rig_crc32)},
                           {"captures", r.captures},
                           {"captures_crc32", text(r.captures_crc32)},
                           {"target_path", text(r.target_path)},
                           {"board", text(r.board)},
                           {"figures", figures.count(r.id) ? figures[r.id] : nlohmann::json::object()},
                           {"views_set_aside", !views_kept         ? nlohmann::json()
                                               : views.count(r.id) ? views[r.id]
                                                                   : nlohmann::json::array()}});
  }
  std::printf("%s\n", JsonReportText(out).c_str());
  return kExitOk;
}

int PrintHistory(const std::string& db) {
  const auto runs = ReadHistoryRuns(db);
  if (runs.empty()) {  // an empty file provisioned for it, or a history no run was appended to
    std::printf("0 runs: %s holds none yet (each check appends one)\n", db.c_str());
    return kExitOk;
  }
  const auto trends = ReadHistoryTrends(db);
  std::fputs(FormatTrends(runs, trends, ReadHistorySetAside(db)).c_str(), stdout);
  std::fputs(FormatRunSeries(runs, trends, kHistoryRunsListed).c_str(), stdout);
  return kExitOk;
}

}  // namespace

int RunCheck(int argc, char** argv) {
  CLI::App app{
      "The nightly recalibration check. Take 8 to 10 fresh captures of the double-sided target (lasers off, the "
      "target in different poses between the modules, within ~65 deg of facing each camera: a view seen 70 deg or "
      "more from face-on is set aside; at least 5 must keep a view once views whose corners "
      "are misplaced are set aside, or the night is refused) and run this against the stored rig file. The calibration "
      "is held fixed; only the board poses are re-estimated. It reports each camera's consistency with the others, "
      "each module's stereo consistency and rectified-row error, and each module pair's closure through the "
      "target, each next to a threshold derived from the stored calibration's own residuals and uncertainties. "
      "It names the camera or module that changed, says whether a new pose or a new lens (focal length, principal "
      "point) explains a named camera's corners, either (it cannot tell) or neither alone, and appends the run to "
      "an SQLite history (once: the same captures checked again with the same rig file are not appended twice).\n\n"
      "A night that cannot say ok though every figure is within its threshold (a view set aside as taken at "
      "another moment in its camera's last capture, where a knock reads the same; or images many times noisier "
      "than the calibration's) reads recapture: capture again before production, exit 1 as recalibrate.\n\n"
      "Exit codes: 0 ok; 1 recalibrate or recapture; 2 bad usage or input.\n\n"
      "Examples:\n"
      "  stereorig check --rig rig.yaml --captures tonight/ --target target.yaml --report tonight/check.json\n"
      "  stereorig check --history --rig rig.yaml          (the trend of every figure)",
      "stereorig check"};
  std::string rig_path, captures, target_path, report_path, history_db;
  bool history_only = false, history_json = false;
  CheckOptions options;
  app.add_option("--rig", rig_path,
                 "the stored rig file (from stereorig calibrate); required, but with --history only where the history "
                 "is looked for by default (give it or --history-db)");
  app.add_option("--captures", captures,
                 "folder of captures: one sub-folder per capture with camK.png per camera (or a simulated "
                 "dataset, whose calibration/ folder is used); required unless --history");
  app.add_option("--target", target_path,
                 "the target file (YAML) of the board in the captures: the board the rig was calibrated with (the rig "
                 "file records it, and the plate's back_from_front as calibrated, which the check uses; another board "
                 "is refused); required unless --history");
  app.add_option("--history-db", history_db, "SQLite history (default: check-history.sqlite beside the rig file)")
      ->check(NonEmptyPath());  // '' fell back to the default: another database than the one named
  app.add_option("--report", report_path, "write the figures as JSON here")->check(NonEmptyPath());
  app.add_option("--k-sigma", options.k_sigma,
                 "coverage factor of every threshold, in (0, 10]: each is its figure's expected value on an "
                 "unchanged rig plus k of its standard deviations (a closure's: the chi-square quantile at that "
                 "level), and the calibration's own projection uncertainty at k")
      ->capture_default_str();
  app.add_flag("--history", history_only,
               "print the trend of every figure from the history, then its last runs one a line, and stop");
  app.add_flag("--json", history_json,
               "with --history: print every run as JSON instead (its inputs, k_sigma, figures and views set aside)");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  if (history_json && !history_only)
    throw InputError("--json", "applies only with --history (a check's own JSON is its --report)");
  const bool history_given = !history_db.empty();
  // --history reads no rig, but a rig given is where it looks for the
  // history by default: a mistyped one (or one beside a history, with
  // --history-db) printed a history and exited 0, the slip unnoticed.
  if (history_only && !rig_path.empty()) RequireInputFile(rig_path, /*pipe_too=*/true);
  if (history_db.empty()) {
    if (rig_path.empty()) throw InputError("", "give --rig or --history-db");
    // The history lives beside the rig file: a rig given as a pipe
    // (`--rig <(...)`) has no folder to keep it in (/dev/fd/), which would
    // fail only after the whole check.
    std::error_code ec;
    if (std::filesystem::is_fifo(rig_path, ec))
      throw InputError("--rig", rig_path + " is a pipe, with no folder for the history beside it: give --history-db");
    history_db = DefaultHistoryPath(rig_path);
  }
  if (history_only) {
    // It reads the history alone: options for a check would be ignored.
    for (const char* flag : {"--captures", "--target", "--report", "--k-sigma"})
      if (app.count(flag) > 0) throw InputError(flag, "does not apply with --history (it prints the trend and stops)");
    return history_json ? PrintHistoryJson(history_db) : PrintHistory(history_db);
  }
  if (rig_path.empty() || captures.empty() || target_path.empty()) {
    throw InputError("", "--rig, --captures and --target are required (see --help)");
  }
  try {
    options.Check();
  } catch (const InputError& e) {  // named by the flag that set it
    if (e.where() == "k_sigma") throw InputError("--k-sigma", e.problem());
    throw;
  }
  // The report and the history checked before the target is detected: a
  // report over the rig file, or into a folder that is not there, would
  // fail (or destroy the rig file) only after the work.
  OutputPaths outputs;
  outputs.Protect(rig_path, "the rig file (--rig)");
  outputs.Protect(target_path, "the target file (--target)");
  for (const std::string& image : CaptureFolderImages(captures)) outputs.Protect(image, "a capture image (--captures)");
  if (!report_path.empty()) outputs.Claim(report_path, "the report (--report)");
  outputs.Claim(history_db, history_given ? "the history database (--history-db, updated in place)"
                                          : "the history database (by default beside the rig file, updated in place)");

  std::string rig_bytes;
  const Rig rig = ReadRigFile(rig_path, &rig_bytes);
  const std::string rig_crc32 = Crc32Hex(rig_bytes);  // of the bytes parsed
  // The files as the history keeps them, resolved as they are read: a link
  // re-pointed during the minutes of detection would name another file.
  const std::string rig_kept_as = HistoryPathOf(rig_path);
  RequireCalibrationResiduals(rig, rig_path);  // named by the rig file, before minutes of detection
  // The board with the back_from_front the calibration ended with (S holds
  // with it); a board other than the calibration's is refused here.
  const CheckTarget check_target = TargetForCheck(rig, ReadTargetFile(target_path), target_path);
  const std::string target_kept_as = HistoryPathOf(target_path);
  const std::string captures_kept_as = HistoryPathOf(captures);
  const std::string captures_crc32 = CapturesCrc32Hex(captures);  // as read now, as the rig's
  const Target& target = check_target.target;
  RejectCamerasBeyondTheRig(captures, rig.num_cameras());
  // A history that is not ours is refused before any work, so a failed run
  // leaves neither a report nor a half-recorded night.
  if (std::filesystem::exists(history_db)) {
    ReadHistoryRuns(history_db);
    RequireHistoryWritable(history_db);
  }
  RequireCapturesFolder(captures);  // before the progress line
  std::fprintf(stderr, "check: detecting the target in %s\n", captures.c_str());
  // Every image held to the rig's size for its camera, as reconstruct
  // does: against the first capture's instead, an odd-sized image there
  // got the right ones after it blamed.
  CaptureFolderOptions per_folder;
  per_folder.progress = true;
  for (int c = 0; c < rig.num_cameras(); ++c)
    per_folder.rig_cameras.push_back(
        {"cam" + std::to_string(c), rig.camera(c).imager_width_px(), rig.camera(c).imager_height_px()});
  per_folder.incomplete_set_aside = true;  // 8 to 10 captures leave room for one lost
  const DetectedCaptures detected = DetectCaptureFolder(captures, target, rig.num_cameras(), per_folder);
  // Sub-folders taken for no capture are named, as calibrate does: a
  // capture hidden by mistake (.005) lost a night's views without a word.
  for (const std::string& skipped : detected.skipped_folders)
    std::printf("skipped %s: not a capture (a hidden folder, or one holding no image)\n",
                PrintableText(skipped).c_str());
  // A capture missing a camera's image is set aside whole, as an empty one
  // is skipped: 8 to 10 captures leave room for one lost (refused, it cost
  // the night). Said on stdout with the set-aside views, and warned: the
  // camera's cable or its trigger may be what failed. Too few left: refused
  // naming the files, as every missing image was before.
  if (!detected.missing_images.empty() && detected.num_captures < options.min_captures) {
    std::string all;
    for (const std::string& missing : detected.missing_images) all += (all.empty() ? "" : ", ") + missing;
    throw InputError(detected.missing_images.front(),
                     "missing or empty (each capture needs camK.png for every camera; " +
                         std::to_string(detected.missing_images.size()) + " missing: " + all + "): only " +
                         std::to_string(detected.num_captures) + " captures are complete, the check needs " +
                         std::to_string(options.min_captures));
  }
  // One line a capture, each of its files missing or empty (0 bytes).
  auto state = [](const std::string& image) { return std::filesystem::exists(image) ? "empty (0 bytes)" : "missing"; };
  for (size_t i = 0; i < detected.missing_images.size();) {
    const std::filesystem::path capture = std::filesystem::path(detected.missing_images[i]).parent_path();
    std::string files;
    for (; i < detected.missing_images.size() &&
           std::filesystem::path(detected.missing_images[i]).parent_path() == capture;
         ++i)
      files += (files.empty() ? "" : ", ") +
               PrintableText(std::filesystem::path(detected.missing_images[i]).filename().string()) + " " +
               state(detected.missing_images[i]);
    std::printf("set aside: capture %s whole: %s; not used\n", PrintableText(capture.filename().string()).c_str(),
                files.c_str());
  }
  FlushStdout();
  for (const std::string& missing : detected.missing_images)
    std::fprintf(stderr, "stereorig check: warning: %s: %s; its capture set aside, the night judged without it\n",
                 PrintableText(missing).c_str(), state(missing));
  std::fprintf(stderr, "check: %d captures, %zu views; re-estimating board poses\n", detected.num_captures,
               detected.observations.size());
  CheckResult result = RunCheckNamingExchangedImages(rig, target, detected, options, captures);
  result.target_note = check_target.note;  // said with a failing night (the explanation's end)
  // A board printed off its file: the rig agrees with itself, but its scale
  // cannot be checked against a board of unknown size. Neither ok nor
  // recalibrate (against this file every baseline and S would take the
  // print's error): bad input, exit 2, nothing written.
  if (result.shared_scale_print_only) throw InputError(target_path, result.Explanation());

  std::printf("%-44s %10s %10s %6s %8s\n", "figure", "value", "threshold", "pass", "samples");
  nlohmann::json report = {{"rig", rig_path},
                           {"rig_crc32", rig_crc32},
                           {"captures", captures},
                           {"captures_crc32", captures_crc32},
                           {"date_utc", NowUtcIso8601()},
                           {"k_sigma", options.k_sigma},
                           {"skipped_folders", detected.skipped_folders},
                           {"missing_images", detected.missing_images}};
  for (const CheckFigure& f : result.figures) {
    std::printf("%-44s %10.4f %10.4f %6s %8d\n", f.name.c_str(), f.value, f.threshold, f.pass ? "yes" : "NO",
                f.samples);
    report["figures"].push_back(
        {{"name", f.name}, {"value", f.value}, {"threshold", f.threshold}, {"pass", f.pass}, {"samples", f.samples}});
  }
  // Views set aside whole: their board seen nearly edge-on (its corners can
  // share one error no noise of their own shows), their corners fit no board
  // pose, not even their own (a detection slip), or they
  // disagree with their capture's other views in that capture only (an
  // image taken at another moment). A capture set aside whole is said once,
  // with why: each of its views printed "off the capture's other views"
  // read as if each had slipped alone.
  // The captures said whole are kept, not read off the entries' order: a
  // view set aside for its corners' jumps comes before the rest of its
  // capture going whole, and a whole line said only after another capture's
  // entry left such a capture unsaid.
  report["views_set_aside"] = nlohmann::json::array();
  std::set<int> said_whole;
  for (const SetAsideView& v : result.views_set_aside) {
    const auto name = detected.capture_names.find(v.capture);
    const std::string capture = name != detected.capture_names.end() ? name->second : std::to_string(v.capture);
    const bool other_moment = v.why == SetAsideWhy::kOtherMoment;
    const bool edge_on = v.why == SetAsideWhy::kEdgeOn;
    const bool whole = v.whole_capture != WholeCapture::kNo;
    if (whole && said_whole.insert(v.capture).second) {
      std::string cameras;  // those that went with the capture (a view set aside before is said on its own)
      for (const SetAsideView& w : result.views_set_aside)
        if (w.capture == v.capture && w.whole_capture != WholeCapture::kNo)
          cameras += (cameras.empty() ? "cam" : ", cam") + std::to_string(w.camera);
      std::printf("set aside: capture %s whole (%s): %s; not used\n", capture.c_str(), cameras.c_str(),
                  WholeCaptureText(v).c_str());
    } else if (edge_on) {
      std::printf(
          "set aside: capture %s cam%d: board seen %.0f deg from face-on (edge-on: its corners can share one "
          "error), not used\n",
          capture.c_str(), v.camera, v.tilt_deg);
    } else if (!whole) {
      std::printf(other_moment ? "set aside: capture %s cam%d: off the capture's other views by %.3f px (bound %.3f "
                                 "px), in this capture only: taken at another moment than the capture's other "
                                 "views?, not used\n"
                               : "set aside: capture %s cam%d: its corners jump about their own board pose by %.3f "
                                 "px (bound %.3f px): misplaced (taken for the wrong squares, or far noisier than the "
                                 "camera's other views), not used\n",
                  capture.c_str(), v.camera, v.FigurePx(), v.bound_px);
    }
    nlohmann::json entry = {
        {"capture", capture},
        {"camera", v.camera},
        {"why", other_moment ? "other_moment"
                : edge_on    ? "edge_on"
                             : "corners_jump"},
        {other_moment ? "off_px" : "jump_rms_px", v.FigurePx()},
        {"bound_px", v.bound_px},
        {"left_open", v.left_open},
        {"whole_capture", v.whole_capture == WholeCapture::kModulesDisagree ? nlohmann::json("modules_disagree")
                          : v.whole_capture == WholeCapture::kViewOrModule  ? nlohmann::json("view_or_module")
                                                                            : nlohmann::json()}};
    // An edge-on view: its tilt and the tilt that set it aside; its
    // jump_rms_px and bound_px are the jump screen's reading of it.
    if (edge_on) entry["tilt_deg"] = v.tilt_deg, entry["bound_deg"] = kEdgeOnTiltDeg;
    report["views_set_aside"].push_back(entry);
  }
  // The board's size as each module measures it, over the squares measured
  // with (the target file's, or the record's where it re-measured them;
  // board_scale.h): a wrong --target reads off alike on every module.
  report["board_scale"] = nlohmann::json::array();
  for (const ModuleBoardScale& m : result.board_scales) {
    std::printf("board size: module %d measures it %+.3f%% against squares of %s mm (median of %d captures)\n",
                m.module, 100 * (m.scale - 1), NumberText(target.square_size_mm(), 12).c_str(), m.captures);
    report["board_scale"].push_back({{"module", m.module}, {"scale", m.scale}, {"captures", m.captures}});
  }
  // The board measured with (check_target.h).
  if (check_target.back_from_front_as_calibrated)
    std::printf("target: back_from_front as calibrated (the rig file's), %.4f mm and %.4f deg from the target file's\n",
                check_target.calibrated_vs_file_mm, check_target.calibrated_vs_file_deg);
  if (!check_target.note.empty()) std::printf("note: %s\n", PrintableText(check_target.note).c_str());
  report["target"] = {{"as_calibrated", check_target.as_calibrated},
                      {"calibrated_with", nullptr},
                      {"back_from_front_as_calibrated", check_target.back_from_front_as_calibrated},
                      {"calibrated_vs_file_mm", check_target.calibrated_vs_file_mm},
                      {"calibrated_vs_file_deg", check_target.calibrated_vs_file_deg},
                      {"file_vs_filed_mm", check_target.file_vs_filed_mm},
                      {"file_vs_filed_deg", check_target.file_vs_filed_deg},
                      {"note", nullptr}};
  if (!check_target.calibrated_with.empty()) report["target"]["calibrated_with"] = check_target.calibrated_with;
  if (!check_target.note.empty()) report["target"]["note"] = check_target.note;
  report["board_size_note"] = nullptr;
  if (!result.board_size_note.empty()) report["board_size_note"] = result.board_size_note;
  // Tonight's noise against the calibration's, and where it is many times
  // that, why the thresholds then see little (the verdict reads recapture).
  report["corner_noise"] = nlohmann::json::array();
  for (const CameraNoise& n : result.corner_noise)
    report["corner_noise"].push_back(
        {{"camera", n.camera}, {"tonight_px", n.tonight_px}, {"calibration_px", n.calibration_px}});
  const std::string noise_warning = result.NoiseWarning();
  report["noise_warning"] = noise_warning.empty() ? nlohmann::json() : nlohmann::json(noise_warning);
  if (!noise_warning.empty()) {
    FlushStdout();  // before the warning, where both go to one log
    std::fprintf(stderr, "stereorig check: warning: %s\n", noise_warning.c_str());
  }
  std::printf("verdict: %s (%s)\n", result.Verdict().c_str(), result.Explanation().c_str());
  report["verdict"] = result.Verdict();
  report["explanation"] = result.Explanation();
  // Every camera and module named. moved_cameras and moved_modules are
  // their old names, with their old contents: a nightly alarm built on them
  // still fires for everything named (narrowed, they fell silent on a lens
  // drift, on a module shift, and on a turned camera whose lens fit passes
  // too, a second reading found). What explains each: camera_changes' kind,
  // closure_modules and split_modules.
  report["flagged_cameras"] = report["moved_cameras"] = result.FlaggedCameras();
  report["flagged_modules"] = report["moved_modules"] = result.FlaggedModules();
  // Each named camera: what explains its corners (a new pose, a new lens,
  // either, neither, or too few corners to fit), with both fits' residuals
  // (null when not fitted) and the lens fit's estimate.
  report["camera_changes"] = nlohmann::json::array();  // present, if empty, as the lists above
  for (const CameraChange& c : result.camera_changes) {
    report["camera_changes"].push_back({{"camera", c.camera},
                                        {"kind", CameraChangeKindName(c.kind)},
                                        {"corners", c.corners},
                                        {"moved_fit_rms_px", c.moved_rms_px},
                                        {"lens_fit_rms_px", c.lens_rms_px},
                                        {"threshold_px", c.threshold_px},
                                        {"turned_deg", c.turned_deg},
                                        {"shifted_mm", c.shifted_mm},
                                        {"focal_percent", c.focal_percent},
                                        {"principal_point_px", {c.principal_point_px.x(), c.principal_point_px.y()}}});
    if (!std::isfinite(c.turned_deg)) {  // no pose fit, or its solve failed: no motion to report
      report["camera_changes"].back()["turned_deg"] = nullptr;
      report["camera_changes"].back()["shifted_mm"] = nullptr;
    }
    if (c.kind == CameraChangeKind::kNotFitted) {  // no estimate, not an estimate of no change
      report["camera_changes"].back()["focal_percent"] = nullptr;
      report["camera_changes"].back()["principal_point_px"] = nullptr;
    }
  }
  report["closure_modules"] = result.closure_modules;
  report["closure_which_unknown"] = result.closure_which_unknown;
  report["split_modules"] = result.split_modules;
  // A change every camera shares, or the rig's scale against the board's,
  // where it explains the night (nothing is then named alone).
  // The cameras named besides a shared change, each in camera_changes
  // (read against the others with the shared change applied).
  report["shared_lens_besides"] = result.shared_lens_besides;
  report["shared_lens_change"] = nullptr;
  if (result.shared_lens_explains) {
    const SharedLensChange& shared = result.shared_lens_change;
    report["shared_lens_change"] = {
        {"focal_percent", shared.focal_percent},
        {"principal_point_px", {shared.principal_point_px.x(), shared.principal_point_px.y()}},
        {"turn_equivalent_deg", shared.turn_equivalent_deg}};
  }
  // A module that moved as a whole besides a lens of it (module_shift.h),
  // against the modules it was read against: which of them moved the
  // check can tell only where the closures name the module alone (with two
  // modules, module 1 moved reads as module 0's shift).
  report["module_shifts"] = nlohmann::json::array();
  for (const CheckResult::ModuleShiftNamed& m : result.module_shifts)
    report["module_shifts"].push_back({{"module", m.module},
                                       {"shift_mm", m.shift_mm.norm()},
                                       {"shift_mm_xyz", {m.shift_mm.x(), m.shift_mm.y(), m.shift_mm.z()}},
                                       {"relative_to", m.relative_to},
                                       {"which_unknown", m.which_unknown}});
  report["shared_scale"] = nullptr;
  report["shared_scale_print_only"] = nullptr;
  if (result.shared_scale_explains) {
    report["shared_scale"] = result.shared_scale;
    report["shared_scale_print_only"] = result.shared_scale_print_only;
  }

  // The history appended, the report staged in its temporary file within
  // the append's transaction (with what became of the run: its id, or the
  // run of the same night it repeats), then the report renamed in: a report
  // that cannot be written (a full disk) leaves the history without the
  // night. A history that refuses the run after all (checked writable
  // above, but another process may hold it now) does not cost the night its
  // verdict: the report says why the run is not in the history, a warning
  // too, and the exit code is the verdict's.
  // Paths as resolved when the files were read (HistoryPathOf), rig_file
  // and rig_path alike.
  HistoryRun run{0, report["date_utc"], rig_kept_as, captures_kept_as, "", ""};
  run.rig_path = rig_kept_as;
  run.rig_crc32 = rig_crc32;
  run.target_path = target_kept_as;
  run.board = check_target.back_from_front_as_calibrated ? "as calibrated" : "the target file's";
  run.k_sigma = options.k_sigma;
  run.captures_crc32 = captures_crc32;
  AtomicOutputSet staged_report;
  bool report_failed = false;
  auto stage_report = [&](const nlohmann::json& history) {
    if (report_path.empty()) return;
    report["history"] = history;
    try {
      staged_report = AtomicOutputSet();  // what a failed commit staged before, removed
      staged_report.Add(report_path, JsonReportText(report) + "\n");
    } catch (...) {
      report_failed = true;
      throw;
    }
  };
  nlohmann::json history = {{"db", history_db},
                            {"appended", false},
                            {"run_id", nullptr},
                            {"same_night_as_run", nullptr},
                            {"not_appended_why", nullptr}};
  std::string not_appended, not_appended_why;  // short (stdout) and whole (the warning, the report)
  try {
    AppendToHistory(history_db, run, result, detected.capture_names, [&](const HistoryAppend& outcome) {
      if (outcome.same_night) {
        const HistoryRun& same = *outcome.same_night;
        not_appended =
            "the same night as run " + std::to_string(same.id) + " (" + same.date_utc + ", " + same.verdict + ")";
        not_appended_why = not_appended + ": these captures (crc32 " + captures_crc32 + ") with this rig file (crc32 " +
                           rig_crc32 + ") were checked then; the history keeps each night once";
        if (same.k_sigma != options.k_sigma)
          not_appended_why +=
              " (that run's k_sigma: " + (same.k_sigma ? NumberText(*same.k_sigma) : std::string("unknown")) +
              ", tonight's: " + NumberText(options.k_sigma) + ")";
        history["same_night_as_run"] = same.id;
        history["not_appended_why"] = not_appended_why;
      } else {
        history["appended"] = true;
        history["run_id"] = outcome.run_id;
      }
      stage_report(history);
    });
  } catch (const InputError& e) {
    if (report_failed) throw;  // the report's failure: the history rolled back, exit 2
    // The database's own problem (the line names it), or another file's
    // (its journal beside it) with its path. Not appended, so these
    // captures checked again are no repeat: they add the night.
    not_appended = "it could not be written";
    not_appended_why = "the history could not be written (" + (e.where() == history_db ? e.problem() : e.what()) +
                       "): check these captures again to add the night";
    history["appended"] = false, history["run_id"] = nullptr, history["same_night_as_run"] = nullptr;
    history["not_appended_why"] = not_appended_why;
    stage_report(history);
  }
  staged_report.Commit();
  if (history["appended"] == true) {
    std::printf("history: appended to %s (run %lld)\n", history_db.c_str(), history["run_id"].get<long long>());
  } else {
    std::printf("history: not appended to %s: %s\n", history_db.c_str(), PrintableText(not_appended).c_str());
    FlushStdout();  // before the warning, where both go to one log
    std::fprintf(stderr, "stereorig check: warning: tonight's run is not in the history %s: %s; the verdict stands\n",
                 history_db.c_str(), PrintableText(not_appended_why).c_str());
  }
  // recapture as recalibrate: exit 1, the rig not to be trusted until a night says ok.
  return result.Verdict() == "ok" ? kExitOk : kExitCheckFailed;
}

}  // namespace stereorig
