#include "calib/check/history.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Db = std::unique_ptr<sqlite3, DbCloser>;
struct StmtFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Stmt = std::unique_ptr<sqlite3_stmt, StmtFinalizer>;

constexpr const char* kSchema =
    "CREATE TABLE IF NOT EXISTS stereorig_check_runs ("
    "  id INTEGER PRIMARY KEY AUTOINCREMENT, date_utc TEXT NOT NULL, rig_file TEXT NOT NULL,"
    "  captures TEXT NOT NULL, verdict TEXT NOT NULL, explanation TEXT NOT NULL);"
    "CREATE TABLE IF NOT EXISTS stereorig_check_figures ("
    "  run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id), name TEXT NOT NULL,"
    "  value REAL NOT NULL, threshold REAL NOT NULL, pass INTEGER NOT NULL, samples INTEGER NOT NULL);"
    "CREATE TABLE IF NOT EXISTS stereorig_check_views_set_aside ("
    "  run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id), capture TEXT NOT NULL,"
    "  camera INTEGER NOT NULL, jump_rms_px REAL NOT NULL, bound_px REAL NOT NULL);"
    "CREATE TABLE IF NOT EXISTS stereorig_check_meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);"
    "CREATE TABLE IF NOT EXISTS stereorig_check_run_inputs ("
    "  run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id), rig_path TEXT NOT NULL,"
    "  rig_crc32 TEXT NOT NULL, target_path TEXT NOT NULL, board TEXT NOT NULL);";

constexpr const char* kRunInputsTable = "stereorig_check_run_inputs";

constexpr const char* kSetAsideTable = "stereorig_check_views_set_aside";
constexpr const char* kSetAsideSinceKey = "views_set_aside_since_run";

Db Open(const std::string& path, bool create) {
  if (!create && !std::filesystem::exists(path)) throw InputError(path, "no such history database");
  sqlite3* raw = nullptr;
  const int flags = create ? SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE : SQLITE_OPEN_READONLY;
  if (sqlite3_open_v2(path.c_str(), &raw, flags, nullptr) != SQLITE_OK) {
    const std::string msg = raw ? sqlite3_errmsg(raw) : "cannot open";
    sqlite3_close(raw);
    throw InputError(path, "cannot open history database: " + msg);
  }
  sqlite3_busy_timeout(raw, 5000);
  return Db(raw);
}

void Exec(sqlite3* db, const std::string& sql, const std::string& path) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : "error";
    sqlite3_free(err);
    throw InputError(path, "history database: " + msg);
  }
}

Stmt Prepare(sqlite3* db, const char* sql, const std::string& path) {
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) != SQLITE_OK) {
    throw InputError(path, std::string("history database: ") + sqlite3_errmsg(db));
  }
  return Stmt(s);
}

std::string Text(sqlite3_stmt* s, int col) {
  const unsigned char* t = sqlite3_column_text(s, col);
  return t ? reinterpret_cast<const char*>(t) : "";
}

bool HasTable(sqlite3* db, const char* table, const std::string& path) {
  Stmt s = Prepare(db, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?;", path);
  sqlite3_bind_text(s.get(), 1, table, -1, SQLITE_TRANSIENT);
  return sqlite3_step(s.get()) == SQLITE_ROW;
}

bool HasColumn(sqlite3* db, const char* table, const char* column, const std::string& path) {
  Stmt s = Prepare(db, "SELECT 1 FROM pragma_table_info(?) WHERE name = ?;", path);
  sqlite3_bind_text(s.get(), 1, table, -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.get(), 2, column, -1, SQLITE_TRANSIENT);
  return sqlite3_step(s.get()) == SQLITE_ROW;
}

// True for a history of ours, false for a database that holds nothing at
// all (an empty file, as `install -m 664 /dev/null` provisions one for a
// service user: SQLite reads it as an empty database), which the first
// append makes ours. Anything else is refused: tables of ours added to
// another program's database would mix the two.
bool IsOurHistory(sqlite3* db, const std::string& path) {
  if (HasTable(db, "stereorig_check_runs", path)) return true;
  Stmt s = Prepare(db, "SELECT 1 FROM sqlite_master;", path);
  if (sqlite3_step(s.get()) == SQLITE_ROW)
    throw InputError(path,
                     "an SQLite database, but not a stereorig check history (it has no table stereorig_check_runs): "
                     "give another with --history-db");
  return false;
}

// Columns added to a table after it was first written: a history from
// before gets them at its next append (ALTER TABLE ADD COLUMN), its earlier
// rows reading NULL (unknown).
struct AddedColumn {
  const char* table;
  const char* column;
  const char* type;
};
constexpr AddedColumn kAddedColumns[] = {{"stereorig_check_run_inputs", "k_sigma", "REAL"},
                                         {"stereorig_check_run_inputs", "captures_crc32", "TEXT"}};

void AddMissingColumns(sqlite3* db, const std::string& path) {
  for (const AddedColumn& c : kAddedColumns)
    if (!HasColumn(db, c.table, c.column, path))
      Exec(db, std::string("ALTER TABLE ") + c.table + " ADD COLUMN " + c.column + " " + c.type + ";", path);
}

std::optional<double> OptionalDouble(sqlite3_stmt* s, int col) {
  if (sqlite3_column_type(s, col) == SQLITE_NULL) return std::nullopt;
  return sqlite3_column_double(s, col);
}

// The first run of the same night (the same captures with the same rig
// file), if the history holds one.
std::optional<HistoryRun> SameNight(sqlite3* db, const HistoryRun& run, const std::string& path) {
  if (run.captures_crc32.empty()) return std::nullopt;
  Stmt s = Prepare(db,
                   "SELECT r.id, r.date_utc, r.verdict, r.explanation, i.k_sigma FROM stereorig_check_runs r JOIN "
                   "stereorig_check_run_inputs i ON i.run_id = r.id WHERE i.captures_crc32 = ? AND i.rig_crc32 = ? "
                   "ORDER BY r.id LIMIT 1;",
                   path);
  sqlite3_bind_text(s.get(), 1, run.captures_crc32.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.get(), 2, run.rig_crc32.c_str(), -1, SQLITE_TRANSIENT);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return std::nullopt;
  HistoryRun same;
  same.id = sqlite3_column_int64(s.get(), 0);
  same.date_utc = Text(s.get(), 1), same.verdict = Text(s.get(), 2), same.explanation = Text(s.get(), 3);
  same.k_sigma = OptionalDouble(s.get(), 4);
  same.captures_crc32 = run.captures_crc32, same.rig_crc32 = run.rig_crc32;
  return same;
}

std::string KSigmaText(double k) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", k);
  return text;
}

// Run ids as ranges: "1..3, 7, 9..12".
std::string RunRanges(const std::vector<long long>& ids) {
  std::string out;
  for (size_t i = 0; i < ids.size();) {
    size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    out += (out.empty() ? "" : ", ") + std::to_string(ids[i]) + (j > i ? ".." + std::to_string(ids[j]) : "");
    i = j + 1;
  }
  return out;
}

}  // namespace

std::string HistoryPathOf(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return path;
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  if (ec) return path;
  if (fs::is_regular_file(absolute, ec)) {
    const fs::path canonical = fs::canonical(absolute, ec);
    if (!ec) return canonical.string();
  }
  // Anything else (a folder, a pipe, a path not there): the part that
  // exists resolved, the rest appended. Not lexically_normal: it collapses
  // "link/.." to the folder holding the link, not the one the link names.
  const fs::path weakly = fs::weakly_canonical(absolute, ec);
  if (!ec && !weakly.empty()) return weakly.string();
  // What cannot be resolved (/dev/fd/N names a pipe, not a path): absolute,
  // normalised only where that cannot cross a link.
  for (const fs::path& part : absolute)
    if (part == "..") return absolute.string();
  return absolute.lexically_normal().string();
}

HistoryAppend AppendToHistory(const std::string& path, const HistoryRun& run, const CheckResult& result,
                              const std::map<int, std::string>& capture_names,
                              const std::function<void(const HistoryAppend&)>& before_commit) {
  Db db = Open(path, true);
  Exec(db.get(), "BEGIN IMMEDIATE;", path);
  try {
    IsOurHistory(db.get(), path);  // refuses another program's database
    const bool kept_set_aside = HasTable(db.get(), kSetAsideTable, path);
    Exec(db.get(), kSchema, path);
    AddMissingColumns(db.get(), path);
    HistoryAppend outcome;
    outcome.same_night = SameNight(db.get(), run, path);
    if (outcome.same_night) {  // nothing appended, nothing changed
      if (before_commit) before_commit(outcome);
      Exec(db.get(), "ROLLBACK;", path);
      return outcome;
    }
    Stmt ins = Prepare(db.get(),
                       "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                       "VALUES (?, ?, ?, ?, ?);",
                       path);
    const std::string verdict = result.Verdict(), explanation = result.Explanation();
    const std::string rig_file = HistoryPathOf(run.rig_file), rig_path = HistoryPathOf(run.rig_path);
    const std::string target_path = HistoryPathOf(run.target_path), captures = HistoryPathOf(run.captures);
    sqlite3_bind_text(ins.get(), 1, run.date_utc.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(ins.get(), 2, rig_file.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(ins.get(), 3, captures.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(ins.get(), 4, verdict.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(ins.get(), 5, explanation.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(ins.get()) != SQLITE_DONE)
      throw InputError(path, std::string("history: ") + sqlite3_errmsg(db.get()));
    const long long id = sqlite3_last_insert_rowid(db.get());
    Stmt inputs = Prepare(db.get(),
                          "INSERT INTO stereorig_check_run_inputs (run_id, rig_path, rig_crc32, target_path, board, "
                          "k_sigma, captures_crc32) VALUES (?, ?, ?, ?, ?, ?, ?);",
                          path);
    sqlite3_bind_int64(inputs.get(), 1, id);
    sqlite3_bind_text(inputs.get(), 2, rig_path.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(inputs.get(), 3, run.rig_crc32.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(inputs.get(), 4, target_path.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(inputs.get(), 5, run.board.c_str(), -1, SQLITE_TRANSIENT);
    // Either unknown: left unbound, NULL, as in the runs from before they were kept.
    if (run.k_sigma) sqlite3_bind_double(inputs.get(), 6, *run.k_sigma);
    if (!run.captures_crc32.empty())
      sqlite3_bind_text(inputs.get(), 7, run.captures_crc32.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(inputs.get()) != SQLITE_DONE)
      throw InputError(path, std::string("history: ") + sqlite3_errmsg(db.get()));
    Stmt fig = Prepare(db.get(),
                       "INSERT INTO stereorig_check_figures (run_id, name, value, threshold, pass, samples) "
                       "VALUES (?, ?, ?, ?, ?, ?);",
                       path);
    for (const CheckFigure& f : result.figures) {
      sqlite3_reset(fig.get());
      sqlite3_bind_int64(fig.get(), 1, id);
      sqlite3_bind_text(fig.get(), 2, f.name.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_double(fig.get(), 3, f.value);
      sqlite3_bind_double(fig.get(), 4, f.threshold);
      sqlite3_bind_int(fig.get(), 5, f.pass ? 1 : 0);
      sqlite3_bind_int(fig.get(), 6, f.samples);
      if (sqlite3_step(fig.get()) != SQLITE_DONE) {
        throw InputError(path, std::string("history: ") + sqlite3_errmsg(db.get()));
      }
    }
    if (!kept_set_aside) {  // this run is the first to keep them: the earlier ones did not
      Stmt since = Prepare(db.get(), "INSERT OR IGNORE INTO stereorig_check_meta (key, value) VALUES (?, ?);", path);
      const std::string id_text = std::to_string(id);
      sqlite3_bind_text(since.get(), 1, kSetAsideSinceKey, -1, SQLITE_TRANSIENT);
      sqlite3_bind_text(since.get(), 2, id_text.c_str(), -1, SQLITE_TRANSIENT);
      if (sqlite3_step(since.get()) != SQLITE_DONE)
        throw InputError(path, std::string("history: ") + sqlite3_errmsg(db.get()));
    }
    Stmt aside = Prepare(db.get(),
                         "INSERT INTO stereorig_check_views_set_aside (run_id, capture, camera, jump_rms_px, bound_px) "
                         "VALUES (?, ?, ?, ?, ?);",
                         path);
    for (const SetAsideView& v : result.views_set_aside) {
      const auto name = capture_names.find(v.capture);
      const std::string capture = name != capture_names.end() ? name->second : std::to_string(v.capture);
      sqlite3_reset(aside.get());
      sqlite3_bind_int64(aside.get(), 1, id);
      sqlite3_bind_text(aside.get(), 2, capture.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_int(aside.get(), 3, v.camera);
      sqlite3_bind_double(aside.get(), 4, v.FigurePx());  // the figure that set it aside
      sqlite3_bind_double(aside.get(), 5, v.bound_px);
      if (sqlite3_step(aside.get()) != SQLITE_DONE) {
        throw InputError(path, std::string("history: ") + sqlite3_errmsg(db.get()));
      }
    }
    outcome.run_id = id;
    if (before_commit) before_commit(outcome);
    Exec(db.get(), "COMMIT;", path);
    return outcome;
  } catch (...) {
    sqlite3_exec(db.get(), "ROLLBACK;", nullptr, nullptr, nullptr);
    throw;
  }
}

void RequireHistoryWritable(const std::string& path) {
  Db db = Open(path, true);
  // SQLITE_OPEN_READWRITE opens a file the system write-protects read-only,
  // without an error.
  if (sqlite3_db_readonly(db.get(), "main") == 1)
    throw InputError(path,
                     "the history database is read-only: tonight's run could not be recorded (make it "
                     "writable, or give another with --history-db)");
  // A first page changed opens the rollback journal beside the file: a
  // read-only folder fails here, as it would at the append.
  try {
    Exec(db.get(), "BEGIN IMMEDIATE; CREATE TABLE stereorig_check_write_probe (x);", path);
  } catch (const InputError& e) {
    sqlite3_exec(db.get(), "ROLLBACK;", nullptr, nullptr, nullptr);
    throw InputError(
        path, "the history database cannot be written (" + e.problem() + "): tonight's run could not be recorded");
  }
  Exec(db.get(), "ROLLBACK;", path);
}

std::vector<HistoryRun> ReadHistoryRuns(const std::string& path) {
  Db db = Open(path, false);
  if (!IsOurHistory(db.get(), path)) return {};  // empty: no run yet
  // Histories written before the inputs were kept have no such table, and
  // before k_sigma and the captures' CRC were kept, no such columns.
  const bool inputs = HasTable(db.get(), kRunInputsTable, path);
  const std::string sql =
      inputs ? std::string(
                   "SELECT r.id, r.date_utc, r.rig_file, r.captures, r.verdict, r.explanation, i.rig_path, "
                   "i.rig_crc32, i.target_path, i.board, ") +
                   (HasColumn(db.get(), kRunInputsTable, "k_sigma", path) ? "i.k_sigma" : "NULL") + ", " +
                   (HasColumn(db.get(), kRunInputsTable, "captures_crc32", path) ? "i.captures_crc32" : "NULL") +
                   " FROM stereorig_check_runs r LEFT JOIN stereorig_check_run_inputs i ON i.run_id = r.id ORDER BY "
                   "r.id;"
             : "SELECT id, date_utc, rig_file, captures, verdict, explanation FROM stereorig_check_runs ORDER BY id;";
  Stmt s = Prepare(db.get(), sql.c_str(), path);
  std::vector<HistoryRun> runs;
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    HistoryRun run{sqlite3_column_int64(s.get(), 0),
                   Text(s.get(), 1),
                   Text(s.get(), 2),
                   Text(s.get(), 3),
                   Text(s.get(), 4),
                   Text(s.get(), 5)};
    if (inputs) {
      run.rig_path = Text(s.get(), 6), run.rig_crc32 = Text(s.get(), 7);
      run.target_path = Text(s.get(), 8), run.board = Text(s.get(), 9);
      run.k_sigma = OptionalDouble(s.get(), 10), run.captures_crc32 = Text(s.get(), 11);
    }
    // Runs written before rig_file was kept absolute hold it as typed,
    // relative to a folder the history does not know; their rig_path (the
    // same file, made absolute by the same run) says which file it was.
    if (!run.rig_path.empty() && !std::filesystem::path(run.rig_file).is_absolute()) run.rig_file = run.rig_path;
    runs.push_back(run);
  }
  return runs;
}

std::vector<FigureTrend> ReadHistoryTrends(const std::string& path) {
  Db db = Open(path, false);
  if (!IsOurHistory(db.get(), path)) return {};
  Stmt s = Prepare(db.get(),
                   "SELECT f.name, r.id, r.date_utc, f.value, f.threshold, f.pass FROM stereorig_check_figures f "
                   "JOIN stereorig_check_runs r ON r.id = f.run_id ORDER BY f.name, r.id;",
                   path);
  std::vector<FigureTrend> trends;
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    const std::string name = Text(s.get(), 0);
    if (trends.empty() || trends.back().name != name) trends.push_back({name, {}});
    trends.back().points.push_back({sqlite3_column_int64(s.get(), 1), Text(s.get(), 2),
                                    sqlite3_column_double(s.get(), 3), sqlite3_column_double(s.get(), 4),
                                    sqlite3_column_int(s.get(), 5) != 0});
  }
  return trends;
}

HistorySetAsideLog ReadHistorySetAside(const std::string& path) {
  Db db = Open(path, false);
  HistorySetAsideLog log;
  if (!IsOurHistory(db.get(), path)) return log;
  if (!HasTable(db.get(), kSetAsideTable, path)) return log;  // written before views set aside were kept
  log.since_run_id = 1;
  if (HasTable(db.get(), "stereorig_check_meta", path)) {
    Stmt since = Prepare(db.get(), "SELECT value FROM stereorig_check_meta WHERE key = ?;", path);
    sqlite3_bind_text(since.get(), 1, kSetAsideSinceKey, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(since.get()) == SQLITE_ROW) log.since_run_id = sqlite3_column_int64(since.get(), 0);
  }
  Stmt s = Prepare(db.get(),
                   "SELECT r.id, r.date_utc, v.capture, v.camera, v.jump_rms_px, v.bound_px "
                   "FROM stereorig_check_views_set_aside v JOIN stereorig_check_runs r ON r.id = v.run_id "
                   "ORDER BY r.id, v.camera, v.capture;",
                   path);
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    log.views.push_back({sqlite3_column_int64(s.get(), 0), Text(s.get(), 1), Text(s.get(), 2),
                         sqlite3_column_int(s.get(), 3), sqlite3_column_double(s.get(), 4),
                         sqlite3_column_double(s.get(), 5)});
  }
  return log;
}

std::string FormatTrends(const std::vector<HistoryRun>& runs, const std::vector<FigureTrend>& trends,
                         const HistorySetAsideLog& set_aside) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%zu run(s)", runs.size());
  out += line;
  if (!runs.empty())
    out += ", " + runs.front().date_utc + " .. " + runs.back().date_utc + "; last verdict: " + runs.back().verdict +
           " (" + runs.back().explanation + ")";
  out += "\n";
  // The rig files the runs were measured with, in runs of the same one.
  struct Span {
    long long first, last;
    const HistoryRun* run;
  };
  std::vector<Span> spans;
  std::set<std::string> crcs;
  for (const HistoryRun& r : runs) {
    if (r.rig_crc32.empty()) continue;
    crcs.insert(r.rig_crc32);
    if (!spans.empty() && spans.back().run->rig_crc32 == r.rig_crc32)
      spans.back().last = r.id;
    else
      spans.push_back({r.id, r.id, &r});
  }
  if (crcs.size() > 1) {
    out += "rig files: " + std::to_string(crcs.size()) +
           " different ones over these runs (a trend across a recalibration is not one rig's):\n";
    for (const Span& sp : spans) {
      std::snprintf(line, sizeof line, "  runs %lld..%lld: ", sp.first, sp.last);
      out += line + sp.run->rig_path + " (crc32 " + sp.run->rig_crc32 + ", back_from_front " + sp.run->board + ")\n";
    }
  }
  // Each threshold is k_sigma times its figure's sigma: runs at another k
  // failed (or passed) against other thresholds, so the fails counted below
  // are not one k's.
  std::map<std::string, std::vector<long long>> runs_at_k;  // k (or "unknown") -> its runs
  for (const HistoryRun& r : runs) runs_at_k[r.k_sigma ? KSigmaText(*r.k_sigma) : "unknown"].push_back(r.id);
  if (runs_at_k.size() > 1) {
    out += "k_sigma varied over these runs (each run's thresholds and fails are at its own k):";
    for (const auto& [k, ids] : runs_at_k)
      out += std::string(" ") + (k == "unknown" ? "unknown (written before it was kept)" : k) + " in run(s) " +
             RunRanges(ids) + ";";
    out.back() = '\n';
  } else if (!runs.empty()) {
    out += runs.front().k_sigma ? "k_sigma: " + KSigmaText(*runs.front().k_sigma) + " in every run\n"
                                : "k_sigma: not kept (these runs were written by a version that did not keep it)\n";
  }
  std::snprintf(line, sizeof line, "%-40s %5s %10s %10s %10s %10s %10s %6s\n", "figure", "runs", "first", "last", "min",
                "max", "threshold", "fails");
  out += line;
  for (const FigureTrend& t : trends) {
    double lo = t.points.front().value, hi = lo;
    int fails = 0;
    for (const auto& p : t.points) {
      lo = std::min(lo, p.value);
      hi = std::max(hi, p.value);
      fails += !p.pass;
    }
    std::snprintf(line, sizeof line, "%-40s %5zu %10.4f %10.4f %10.4f %10.4f %10.4f %6d\n", t.name.c_str(),
                  t.points.size(), t.points.front().value, t.points.back().value, lo, hi, t.points.back().threshold,
                  fails);
    out += line;
  }
  // Per camera: how many views were set aside, on how many of the runs that
  // kept them, the last run, and the view worst against its bound.
  if (set_aside.since_run_id == 0) {
    out += "views set aside: not kept (these runs were written by a version that did not keep them)\n";
    return out;
  }
  size_t kept_runs = 0;
  std::string since;
  for (const HistoryRun& r : runs) {
    if (r.id < set_aside.since_run_id) continue;
    if (kept_runs++ == 0 && r.id != runs.front().id)
      since = " since run " + std::to_string(r.id) + " (" + r.date_utc + ")";
  }
  std::map<int, std::vector<const HistorySetAside*>> by_camera;
  for (const HistorySetAside& v : set_aside.views) by_camera[v.camera].push_back(&v);
  if (by_camera.empty()) out += "views set aside: none in " + std::to_string(kept_runs) + " run(s)" + since + "\n";
  for (const auto& [camera, views] : by_camera) {
    std::set<long long> run_ids;
    const HistorySetAside* worst = views.front();
    for (const HistorySetAside* v : views) {
      run_ids.insert(v->run_id);
      if (v->jump_rms_px / v->bound_px > worst->jump_rms_px / worst->bound_px) worst = v;
    }
    std::snprintf(line, sizeof line, "views set aside: cam%d %zu view(s) on %zu of %zu run(s)", camera, views.size(),
                  run_ids.size(), kept_runs);
    out += line + since;
    std::snprintf(line, sizeof line, ", last run %lld (", views.back()->run_id);
    out += line + views.back()->date_utc;
    std::snprintf(line, sizeof line, "); the worst against its bound: %.3f px, %.1fx its %.3f px (capture ",
                  worst->jump_rms_px, worst->jump_rms_px / worst->bound_px, worst->bound_px);
    out += line + worst->capture + ", run " + std::to_string(worst->run_id) + ")\n";
  }
  return out;
}

std::string FormatRunSeries(const std::vector<HistoryRun>& runs, const std::vector<FigureTrend>& trends,
                            size_t last_runs) {
  // Per run: how many figures failed, and the figure nearest its threshold
  // (or furthest beyond it).
  struct Worst {
    int fails = 0;
    double ratio = -1;
    std::string name;
  };
  std::map<long long, Worst> worst;
  for (const FigureTrend& t : trends)
    for (const HistoryPoint& p : t.points) {
      Worst& w = worst[p.run_id];
      w.fails += !p.pass;
      const double ratio = p.threshold > 0 ? p.value / p.threshold : 0;
      if (ratio > w.ratio) w.ratio = ratio, w.name = t.name;
    }
  const size_t first = runs.size() > last_runs ? runs.size() - last_runs : 0;
  std::string out = "runs" + (first > 0 ? " (the last " + std::to_string(last_runs) + ")" : std::string()) + ":\n";
  char line[256];
  std::snprintf(line, sizeof line, "%6s  %-20s  %7s  %-11s  %5s  %s\n", "run", "date_utc", "k_sigma", "verdict",
                "fails", "nearest its threshold (value / threshold); why, where not ok");
  out += line;
  for (size_t i = first; i < runs.size(); ++i) {
    const HistoryRun& r = runs[i];
    const auto w = worst.find(r.id);
    std::snprintf(line, sizeof line, "%6lld  %-20s  %7s  %-11s  %5d  ", r.id, r.date_utc.c_str(),
                  r.k_sigma ? KSigmaText(*r.k_sigma).c_str() : "?", r.verdict.c_str(),
                  w != worst.end() ? w->second.fails : 0);
    out += line;
    if (w != worst.end()) {
      std::snprintf(line, sizeof line, "%.2fx ", w->second.ratio);
      out += line + w->second.name;
    }
    if (r.verdict != "ok") out += "; " + r.explanation;
    out += "\n";
  }
  return out;
}

}  // namespace stereorig
