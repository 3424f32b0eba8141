// The nightly check's history: every run appended to an SQLite database, so
// a slow drift shows before it becomes a failure. Each append is one
// transaction: a crash or a full disk leaves the database as it was.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calib/check/nightly_check.h"

namespace stereorig {

struct HistoryRun {
  long long id = 0;
  std::string date_utc;
  // The rig file: AppendToHistory keeps it as HistoryPathOf's (absolute,
  // canonical), as rig_path below. Runs written before were kept as typed
  // (a relative path, relative to a folder not recorded): read back as
  // their rig_path where they have one, as typed where not.
  std::string rig_file;
  // The captures folder, kept as HistoryPathOf's too; runs written before
  // hold it as typed, and read back so (nothing says from which folder).
  std::string captures;
  std::string verdict;  // "ok", "recalibrate" or "recapture"
  std::string explanation;
  // What the night was measured with (empty in runs written before they were
  // kept; paths kept as HistoryPathOf's): the rig file's absolute path and a
  // CRC-32 of its bytes (a rig recalibrated into the same path reads as
  // another), the target file's absolute path, and which back_from_front the
  // closures used.
  std::string rig_path = "";
  std::string rig_crc32 = "";  // 8 hex digits
  std::string target_path = "";
  std::string board = "";  // "as calibrated" (the rig file's record) or "the target file's"
  // The coverage factor every threshold was k times its sigma with
  // (--k-sigma); unknown in runs written before it was kept.
  std::optional<double> k_sigma = std::nullopt;
  // A CRC-32 of the capture images (their names within their capture and
  // their bytes, 8 hex digits): the same night checked again reads as the
  // same; empty in runs written before it was kept.
  std::string captures_crc32 = "";
};

// What became of a run given to AppendToHistory: appended as run_id, or not
// appended because the history already holds the same night (the same
// captures_crc32 with the same rig_crc32) as same_night.
struct HistoryAppend {
  long long run_id = 0;  // 0: not appended
  std::optional<HistoryRun> same_night = std::nullopt;
};

struct HistoryPoint {
  long long run_id = 0;
  std::string date_utc;
  double value = 0;
  double threshold = 0;
  bool pass = true;
};

// One view the check set aside whole on one run (CheckResult's
// views_set_aside): its corners jumped about their own board pose
// (jump_rms_px), or it was off its capture's other views in that capture
// only (jump_rms_px holds that figure, SetAsideView::FigurePx), or its board
// was seen nearly edge-on (tilt_deg; jump_rms_px and bound_px then hold the
// jump screen's reading of it, which did not set it aside).
struct HistorySetAside {
  long long run_id = 0;
  std::string date_utc;
  std::string capture;  // the capture's name as the run printed it (its index if it had none)
  int camera = -1;
  double jump_rms_px = 0;
  double bound_px = 0;
  // Set aside as seen edge-on, this far from face-on; none for the other
  // reasons, and for every view of a run written before edge-on views were
  // set aside (no version before did so).
  std::optional<double> tilt_deg = std::nullopt;
};

// The views set aside as the history holds them, and since which run they
// are kept (the runs before were written by a version that did not keep
// them, which set views aside all the same).
struct HistorySetAsideLog {
  long long since_run_id = 0;  // 0: not kept at all (no run written by a version that keeps them)
  std::vector<HistorySetAside> views;
};

struct FigureTrend {
  std::string name;
  std::vector<HistoryPoint> points;  // oldest first
};

// The path a history keeps for a file, so that one file reads as one path
// whichever folder the check ran from and however it was typed: absolute,
// and canonical (links, "." and ".." resolved) for a regular file; for
// anything else (a folder, a pipe, a path not there) the part that exists
// resolved so (weakly canonical: "link/.." is the folder the link names
// is in, not the link's); what cannot be resolved at all (/dev/fd/N)
// absolute, as typed. A caller resolves each file when it reads it (the
// check: right after reading the rig and target files), not minutes later
// when the run is appended: a link re-pointed meanwhile would name another
// file.
std::string HistoryPathOf(const std::string& path);

// Appends one run, its paths (rig_file, captures, rig_path, target_path)
// kept as HistoryPathOf's (a no-op on paths the caller already resolved). Creates the database (and its tables) if
// missing or empty (an empty file: provisioned for the service user). Throws InputError naming `db_path` if it is not
// an SQLite database of ours or cannot be written. The views the run set aside are stored with it, each capture named
// by capture_names (CheckResult's capture index -> name; the index where it has none). A run whose captures_crc32 and
// rig_crc32 a run in the history already has is not appended (the same night checked again would count twice in
// every trend): the outcome names that run. `before_commit`, if given, is called with the outcome inside the
// transaction: what it throws rolls the run back (the check stages its report there, so that a report that cannot be
// written leaves the history without the night).
HistoryAppend AppendToHistory(const std::string& db_path, const HistoryRun& run, const CheckResult& result,
                              const std::map<int, std::string>& capture_names = {},
                              const std::function<void(const HistoryAppend&)>& before_commit = {});

// Throws InputError naming `db_path` unless an existing history can be
// written: the file read-only, or its folder (SQLite's journal goes beside
// it), or another process holding it. Run before the check's work, so that
// a night's verdict is not lost to a history that refuses it at the end
// (exit 2 after "verdict: recalibrate", a user's walkthrough found). Writes
// nothing (a table created and rolled back).
void RequireHistoryWritable(const std::string& db_path);

std::vector<HistoryRun> ReadHistoryRuns(const std::string& db_path);
std::vector<FigureTrend> ReadHistoryTrends(const std::string& db_path);
// Oldest run first, cameras in order within a run.
HistorySetAsideLog ReadHistorySetAside(const std::string& db_path);

// A readable table: first, when the runs were measured with more than one
// rig file (by CRC-32; the runs that kept none are left out), the runs of
// each, since a trend across a recalibration is not one rig's; the k_sigma
// of the runs (the runs at each where it varied); one row per
// figure, its first and last values, the
// extremes, the last threshold and how many runs failed it; then, per
// camera, the views set aside and on how many of the runs that kept them (a
// camera that loses views night after night: a slipping detection, a dirty
// or loose lens), how many of them were seen edge-on (the board's poses, not
// the camera), and the worst of the others against its bound.
std::string FormatTrends(const std::vector<HistoryRun>& runs, const std::vector<FigureTrend>& trends,
                         const HistorySetAsideLog& set_aside = {});

// The runs one a line, the last `last_runs` of them: date, k_sigma, verdict,
// how many figures failed, the figure nearest its threshold (value over
// threshold), and why where not ok. Tells when a figure began to drift or a
// verdict changed, which the trend's extremes do not.
std::string FormatRunSeries(const std::vector<HistoryRun>& runs, const std::vector<FigureTrend>& trends,
                            size_t last_runs);

}  // namespace stereorig
