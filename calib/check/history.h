// The nightly check's history: every run appended to an SQLite database, so
// a slow drift shows before it becomes a failure. Each append is one
// transaction: a crash or a full disk leaves the database as it was.
#pragma once

#include <string>
#include <vector>

#include "calib/check/nightly_check.h"

namespace stereorig {

struct HistoryRun {
  long long id = 0;
  std::string date_utc;
  std::string rig_file;
  std::string captures;
  std::string verdict;  // "ok" or "recalibrate"
  std::string explanation;
};

struct HistoryPoint {
  long long run_id = 0;
  std::string date_utc;
  double value = 0;
  double threshold = 0;
  bool pass = true;
};

struct FigureTrend {
  std::string name;
  std::vector<HistoryPoint> points;  // oldest first
};

// Appends one run. Creates the database (and its tables) if missing. Throws
// InputError naming `db_path` if it is not an SQLite database of ours or
// cannot be written.
long long AppendToHistory(const std::string& db_path, const HistoryRun& run, const CheckResult& result);

std::vector<HistoryRun> ReadHistoryRuns(const std::string& db_path);
std::vector<FigureTrend> ReadHistoryTrends(const std::string& db_path);

// A readable table: one row per figure, its first and last values, the
// extremes, the last threshold and how many runs failed it.
std::string FormatTrends(const std::vector<HistoryRun>& runs, const std::vector<FigureTrend>& trends);

}  // namespace stereorig
