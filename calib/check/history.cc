#include "calib/check/history.h"

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>

#include "calib/core/input_error.h"
#include "calib/core/printable_text.h"

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

// The tables as a new history gets them. The CHECKs let SQLite itself refuse
// a row no check writes (a figure's value 'abc', a verdict 'banana', a date
// that is a blob), whoever writes it; histories made before them are still
// opened, and every row is checked as it is read (ReadHistory).
constexpr const char* kSchema =
    "CREATE TABLE IF NOT EXISTS stereorig_check_runs ("
    "  id INTEGER PRIMARY KEY AUTOINCREMENT,"
    "  date_utc TEXT NOT NULL CHECK (typeof(date_utc) = 'text' AND date_utc GLOB "
    "'[0-9][0-9][0-9][0-9]-[0-9][0-9]-[0-9][0-9]T[0-9][0-9]:[0-9][0-9]:[0-9][0-9]Z'),"
    "  rig_file TEXT NOT NULL CHECK (typeof(rig_file) = 'text'),"
    "  captures TEXT NOT NULL CHECK (typeof(captures) = 'text'),"
    "  verdict TEXT NOT NULL CHECK (verdict IN ('ok', 'recalibrate', 'recapture')),"
    "  explanation TEXT NOT NULL CHECK (typeof(explanation) = 'text'));"
    "CREATE TABLE IF NOT EXISTS stereorig_check_figures ("
    "  run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id) CHECK (typeof(run_id) = 'integer'),"
    "  name TEXT NOT NULL CHECK (typeof(name) = 'text' AND name <> ''),"
    "  value REAL NOT NULL CHECK (typeof(value) = 'real' AND abs(value) <= 1.7976931348623157e308),"
    "  threshold REAL NOT NULL CHECK (typeof(threshold) = 'real' AND abs(threshold) <= 1.7976931348623157e308),"
    "  pass INTEGER NOT NULL CHECK (pass IN (0, 1)),"
    "  samples INTEGER NOT NULL CHECK (typeof(samples) = 'integer' AND samples >= 0));"
    "CREATE TABLE IF NOT EXISTS stereorig_check_views_set_aside ("
    "  run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id) CHECK (typeof(run_id) = 'integer'),"
    "  capture TEXT NOT NULL CHECK (typeof(capture) = 'text'),"
    "  camera INTEGER NOT NULL CHECK (typeof(camera) = 'integer' AND camera >= 0),"
    "  jump_rms_px REAL NOT NULL CHECK (typeof(jump_rms_px) = 'real' AND jump_rms_px BETWEEN 0 AND "
    "1.7976931348623157e308),"
    "  bound_px REAL NOT NULL CHECK (typeof(bound_px) = 'real' AND bound_px BETWEEN 0 AND 1.7976931348623157e308));"
    "CREATE TABLE IF NOT EXISTS stereorig_check_meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);"
    "CREATE TABLE IF NOT EXISTS stereorig_check_run_inputs ("
    "  run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id) CHECK (typeof(run_id) = 'integer'),"
    "  rig_path TEXT NOT NULL CHECK (typeof(rig_path) = 'text'),"
    "  rig_crc32 TEXT NOT NULL CHECK (rig_crc32 = '' OR (length(rig_crc32) = 8 AND rig_crc32 NOT GLOB "
    "'*[^0-9a-f]*')),"
    "  target_path TEXT NOT NULL CHECK (typeof(target_path) = 'text'),"
    "  board TEXT NOT NULL CHECK (typeof(board) = 'text'));";

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
constexpr AddedColumn kAddedColumns[] = {
    {"stereorig_check_run_inputs", "k_sigma",
     "REAL CHECK (k_sigma IS NULL OR (typeof(k_sigma) = 'real' AND k_sigma > 0 AND k_sigma <= "
     "1.7976931348623157e308))"},
    {"stereorig_check_run_inputs", "captures_crc32",
     "TEXT CHECK (captures_crc32 IS NULL OR (length(captures_crc32) = 8 AND captures_crc32 NOT GLOB "
     "'*[^0-9a-f]*'))"},
    // A view set aside as seen edge-on: its board's tilt from face-on, deg
    // (NULL: set aside for another reason; every view of a run from before).
    {kSetAsideTable, "tilt_deg",
     "REAL CHECK (tilt_deg IS NULL OR (typeof(tilt_deg) = 'real' AND tilt_deg BETWEEN 0 AND 90))"}};

void AddMissingColumns(sqlite3* db, const std::string& path) {
  for (const AddedColumn& c : kAddedColumns)
    if (!HasColumn(db, c.table, c.column, path))
      Exec(db, std::string("ALTER TABLE ") + c.table + " ADD COLUMN " + c.column + " " + c.type + ";", path);
}

// A history from before the verdict recapture refuses it (its runs table's
// CHECK lists ok and recalibrate alone): the table is rebuilt with kSchema's
// (SQLite cannot alter a CHECK), its rows and ids kept, at the append.
void AllowRecaptureVerdict(sqlite3* db, const std::string& path) {
  Stmt s = Prepare(db, "SELECT sql FROM sqlite_master WHERE type = 'table' AND name = 'stereorig_check_runs';", path);
  if (sqlite3_step(s.get()) != SQLITE_ROW || Text(s.get(), 0).find("'recapture'") != std::string::npos) return;
  s.reset();
  // What a plant added to the table (an index, a trigger that raises an
  // alert on a verdict not ok) goes with the old table when it is dropped,
  // and the AUTOINCREMENT counter would restart at the largest id kept (a
  // deleted last run's id reused): both read first, put back after.
  std::vector<std::string> attached;
  Stmt a = Prepare(db,
                   "SELECT sql FROM sqlite_master WHERE tbl_name = 'stereorig_check_runs' AND type IN ('index', "
                   "'trigger') AND sql IS NOT NULL ORDER BY type, name;",
                   path);
  while (sqlite3_step(a.get()) == SQLITE_ROW) attached.push_back(Text(a.get(), 0));
  a.reset();
  sqlite3_int64 last_id = 0;
  if (HasTable(db, "sqlite_sequence", path)) {
    Stmt q = Prepare(db, "SELECT seq FROM sqlite_sequence WHERE name = 'stereorig_check_runs';", path);
    if (sqlite3_step(q.get()) == SQLITE_ROW) last_id = sqlite3_column_int64(q.get(), 0);
  }
  // legacy_alter_table: the other tables' REFERENCES keep naming
  // stereorig_check_runs, not the old table renamed and dropped.
  Exec(db,
       "PRAGMA legacy_alter_table = ON;"
       "ALTER TABLE stereorig_check_runs RENAME TO stereorig_check_runs_before_recapture;" +
           std::string(kSchema) +
           "INSERT INTO stereorig_check_runs (id, date_utc, rig_file, captures, verdict, explanation) SELECT id, "
           "date_utc, rig_file, captures, verdict, explanation FROM stereorig_check_runs_before_recapture;"
           "DROP TABLE stereorig_check_runs_before_recapture;"
           "PRAGMA legacy_alter_table = OFF;",
       path);
  for (const std::string& sql : attached) Exec(db, sql + ";", path);
  const std::string id = std::to_string(last_id);
  Exec(db,
       "UPDATE sqlite_sequence SET seq = max(seq, " + id +
           ") WHERE name = 'stereorig_check_runs';"
           "INSERT INTO sqlite_sequence (name, seq) SELECT 'stereorig_check_runs', " +
           id + " WHERE " + id +
           " > 0 AND NOT EXISTS (SELECT 1 FROM sqlite_sequence WHERE name = 'stereorig_check_runs');",
       path);
}

std::string KSigmaText(double k) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", k);
  return text;
}

// A value as a message shows it: text quoted (escaped, and cut where long),
// a blob by its size, a number as SQLite holds it.
std::string Shown(sqlite3_stmt* s, int col) {
  switch (sqlite3_column_type(s, col)) {
    case SQLITE_NULL:
      return "NULL";
    case SQLITE_BLOB:
      return "a blob of " + std::to_string(sqlite3_column_bytes(s, col)) + " bytes";
    case SQLITE_TEXT: {
      const std::string text = Text(s, col);
      return "'" + PrintableText(text.size() > 40 ? text.substr(0, 40) + "..." : text) + "'";
    }
    default: {
      char number[32];
      std::snprintf(number, sizeof number, "%.6g", sqlite3_column_double(s, col));
      return number;
    }
  }
}

// A bad row: `where` is its table and rowid.
[[noreturn]] void RefuseRow(const std::string& path, const std::string& where, const std::string& problem) {
  throw InputError(path, "a bad row in the history: " + where + ": " + problem +
                             " (mend or delete the row with sqlite3, or give another history with --history-db)");
}

// One row of a history table as it is read, each value checked. SQLite
// keeps whatever was put in a column (a REAL column keeps 'abc' as text, a
// table made by hand has no NOT NULL), and read unchecked a corrupt row was
// a figure of 0.0000, a nameless figure, a verdict 'banana', and exit 0. A
// bad value throws InputError naming the database, the table, the row and
// what is wrong: the history is not read past it, nor appended to.
class Row {
 public:
  // `s`'s first column is the row's rowid.
  Row(sqlite3_stmt* s, const std::string& path, const char* table)
      : s_(s), path_(path), where_(std::string(table) + " row " + std::to_string(sqlite3_column_int64(s, 0))) {}
  // Said after the row in messages: "(run 3)".
  void Within(const std::string& context) { where_ += " (" + context + ")"; }

  [[noreturn]] void Refuse(const std::string& problem) const { RefuseRow(path_, where_, problem); }
  long long Integer(int col, const std::string& what) const {
    if (sqlite3_column_type(s_, col) != SQLITE_INTEGER) Refuse(what + " is " + Shown(s_, col) + ", not an integer");
    return sqlite3_column_int64(s_, col);
  }
  double Number(int col, const std::string& what) const {
    const int type = sqlite3_column_type(s_, col);
    if (type != SQLITE_FLOAT && type != SQLITE_INTEGER) Refuse(what + " is " + Shown(s_, col) + ", not a number");
    const double v = sqlite3_column_double(s_, col);
    if (!std::isfinite(v)) Refuse(what + " is " + Shown(s_, col) + ", not a finite number");
    return v;
  }
  std::optional<double> OptionalNumber(int col, const std::string& what) const {
    if (sqlite3_column_type(s_, col) == SQLITE_NULL) return std::nullopt;
    return Number(col, what);
  }
  // Text, escaped as PrintableText does: a path's bytes need not be UTF-8
  // (nlohmann::json refuses to write them), a control byte would reach the
  // terminal.
  std::string String(int col, const std::string& what) const {
    if (sqlite3_column_type(s_, col) != SQLITE_TEXT) Refuse(what + " is " + Shown(s_, col) + ", not text");
    return PrintableText(Text(s_, col));
  }
  std::string OptionalString(int col, const std::string& what) const {
    return sqlite3_column_type(s_, col) == SQLITE_NULL ? "" : String(col, what);
  }

 private:
  sqlite3_stmt* s_;
  const std::string& path_;
  std::string where_;
};

bool IsCrc32Text(const std::string& text) {
  return text.size() == 8 &&
         std::all_of(text.begin(), text.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

// "2026-11-20T02:00:00Z", as every run was dated (NowUtcIso8601).
bool IsDateUtcText(const std::string& text) {
  static const char kForm[] = "dddd-dd-ddTdd:dd:ddZ";
  if (text.size() != sizeof kForm - 1) return false;
  for (size_t i = 0; i < text.size(); ++i)
    if (kForm[i] == 'd' ? !std::isdigit(static_cast<unsigned char>(text[i])) : text[i] != kForm[i]) return false;
  return true;
}

// The columns each table of ours was first written with (the ones added
// since are kAddedColumns, a history from before reading them NULL). A table
// without one is no history this program wrote: the read, or the append at
// the end of a night, would fail on it ("no such column").
struct TableColumns {
  const char* table;
  std::vector<const char*> columns;
  bool required;  // false: a table added since, which a history from before lacks
};
const std::vector<TableColumns>& OurTables() {
  static const std::vector<TableColumns> tables = {
      {"stereorig_check_runs", {"id", "date_utc", "rig_file", "captures", "verdict", "explanation"}, true},
      {"stereorig_check_figures", {"run_id", "name", "value", "threshold", "pass", "samples"}, true},
      {kSetAsideTable, {"run_id", "capture", "camera", "jump_rms_px", "bound_px"}, false},
      {"stereorig_check_meta", {"key", "value"}, false},
      {kRunInputsTable, {"run_id", "rig_path", "rig_crc32", "target_path", "board"}, false}};
  return tables;
}

void RequireOurColumns(sqlite3* db, const std::string& path) {
  for (const TableColumns& t : OurTables()) {
    if (!HasTable(db, t.table, path)) {
      if (t.required) throw InputError(path, std::string("a stereorig check history without its table ") + t.table);
      continue;
    }
    for (const char* column : t.columns)
      if (!HasColumn(db, t.table, column, path))
        throw InputError(path, std::string("the history's table ") + t.table + " has no column " + column +
                                   ": not a history stereorig wrote (give another with --history-db)");
  }
}

// Everything a history holds, each row checked as it is read (Row): the
// runs with their inputs, every figure of every run, the views set aside.
struct HistoryContents {
  std::vector<HistoryRun> runs;
  std::vector<FigureTrend> trends;
  HistorySetAsideLog set_aside;
};

std::vector<HistoryRun> ReadRuns(sqlite3* db, const std::string& path) {
  // Histories written before the inputs were kept have no such table, and
  // before k_sigma and the captures' CRC were kept, no such columns.
  const bool inputs = HasTable(db, kRunInputsTable, path);
  std::map<long long, HistoryRun> runs;  // by id
  Stmt s = Prepare(db,
                   "SELECT rowid, id, date_utc, rig_file, captures, verdict, explanation FROM stereorig_check_runs "
                   "ORDER BY rowid;",
                   path);
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    Row row(s.get(), path, "stereorig_check_runs");
    HistoryRun run;
    run.id = row.Integer(1, "its id");
    if (runs.count(run.id)) row.Refuse("a second run " + std::to_string(run.id));
    row.Within("run " + std::to_string(run.id));
    run.date_utc = row.String(2, "its date_utc");
    if (!IsDateUtcText(run.date_utc))
      row.Refuse("its date_utc '" + run.date_utc + "' is not a time as YYYY-MM-DDTHH:MM:SSZ");
    run.rig_file = row.String(3, "its rig_file"), run.captures = row.String(4, "its captures");
    run.verdict = row.String(5, "its verdict");
    if (run.verdict != "ok" && run.verdict != "recalibrate" && run.verdict != "recapture")
      row.Refuse("its verdict '" + run.verdict + "' is neither ok, recalibrate nor recapture");
    run.explanation = row.String(6, "its explanation");
    runs[run.id] = run;
  }
  if (inputs) {
    const std::string sql = std::string("SELECT rowid, run_id, rig_path, rig_crc32, target_path, board, ") +
                            (HasColumn(db, kRunInputsTable, "k_sigma", path) ? "k_sigma" : "NULL") + ", " +
                            (HasColumn(db, kRunInputsTable, "captures_crc32", path) ? "captures_crc32" : "NULL") +
                            " FROM " + kRunInputsTable + " ORDER BY rowid;";
    Stmt in = Prepare(db, sql.c_str(), path);
    std::set<long long> seen;
    while (sqlite3_step(in.get()) == SQLITE_ROW) {
      Row row(in.get(), path, kRunInputsTable);
      const long long id = row.Integer(1, "its run_id");
      const auto run = runs.find(id);
      if (run == runs.end()) row.Refuse("its run_id " + std::to_string(id) + " names no run in stereorig_check_runs");
      if (!seen.insert(id).second) row.Refuse("a second inputs row for run " + std::to_string(id));
      row.Within("run " + std::to_string(id));
      HistoryRun& r = run->second;
      r.rig_path = row.String(2, "its rig_path"), r.rig_crc32 = row.String(3, "its rig_crc32");
      if (!r.rig_crc32.empty() && !IsCrc32Text(r.rig_crc32))
        row.Refuse("its rig_crc32 '" + r.rig_crc32 + "' is not 8 hex digits");
      r.target_path = row.String(4, "its target_path"), r.board = row.String(5, "its board");
      r.k_sigma = row.OptionalNumber(6, "its k_sigma");
      if (r.k_sigma && !(*r.k_sigma > 0)) row.Refuse("its k_sigma " + KSigmaText(*r.k_sigma) + " is not positive");
      r.captures_crc32 = row.OptionalString(7, "its captures_crc32");
      if (!r.captures_crc32.empty() && !IsCrc32Text(r.captures_crc32))
        row.Refuse("its captures_crc32 '" + r.captures_crc32 + "' is not 8 hex digits");
    }
  }
  std::vector<HistoryRun> out;
  for (auto& [id, run] : runs) {
    // Runs written before rig_file was kept absolute hold it as typed,
    // relative to a folder the history does not know; their rig_path (the
    // same file, made absolute by the same run) says which file it was.
    if (!run.rig_path.empty() && !std::filesystem::path(run.rig_file).is_absolute()) run.rig_file = run.rig_path;
    out.push_back(run);
  }
  return out;
}

// The run a row of another table names, which must be in the history: a
// figure of a run that is not there was left out of every trend, unsaid.
const HistoryRun& RunOf(const Row& row, const std::map<long long, const HistoryRun*>& runs, long long id) {
  const auto run = runs.find(id);
  if (run == runs.end()) row.Refuse("its run_id " + std::to_string(id) + " names no run in stereorig_check_runs");
  return *run->second;
}

HistoryContents ReadHistory(sqlite3* db, const std::string& path) {
  RequireOurColumns(db, path);
  HistoryContents h;
  h.runs = ReadRuns(db, path);
  std::map<long long, const HistoryRun*> by_id;
  for (const HistoryRun& r : h.runs) by_id[r.id] = &r;

  // Figures: by name, each one's points oldest run first, once per run.
  std::map<std::string, std::vector<std::pair<HistoryPoint, long long>>> figures;  // name -> (point, rowid)
  Stmt f = Prepare(db,
                   "SELECT rowid, run_id, name, value, threshold, pass, samples FROM stereorig_check_figures "
                   "ORDER BY rowid;",
                   path);
  while (sqlite3_step(f.get()) == SQLITE_ROW) {
    Row row(f.get(), path, "stereorig_check_figures");
    const HistoryRun& run = RunOf(row, by_id, row.Integer(1, "its run_id"));
    row.Within("run " + std::to_string(run.id));
    const std::string name = row.String(2, "its name");
    if (name.empty()) row.Refuse("its name is empty");
    HistoryPoint p;
    p.run_id = run.id, p.date_utc = run.date_utc;
    p.value = row.Number(3, "the value of figure " + name);
    p.threshold = row.Number(4, "the threshold of figure " + name);
    const long long pass = row.Integer(5, "the pass of figure " + name);
    if (pass != 0 && pass != 1)
      row.Refuse("the pass of figure " + name + " is " + std::to_string(pass) + ", not 0 or 1");
    p.pass = pass == 1;
    if (row.Integer(6, "the samples of figure " + name) < 0)
      row.Refuse("the samples of figure " + name + " are negative");
    figures[name].push_back({p, sqlite3_column_int64(f.get(), 0)});
  }
  for (auto& [name, points] : figures) {
    std::stable_sort(points.begin(), points.end(),
                     [](const auto& a, const auto& b) { return a.first.run_id < b.first.run_id; });
    FigureTrend t{name, {}};
    for (size_t i = 0; i < points.size(); ++i) {
      if (i > 0 && points[i].first.run_id == points[i - 1].first.run_id)
        RefuseRow(path,
                  "stereorig_check_figures row " + std::to_string(points[i].second) + " (run " +
                      std::to_string(points[i].first.run_id) + ")",
                  "figure " + name + " a second time in its run (row " + std::to_string(points[i - 1].second) +
                      " is the first)");
      t.points.push_back(points[i].first);
    }
    h.trends.push_back(t);
  }

  // The views set aside, oldest run first, cameras in order within a run.
  if (!HasTable(db, kSetAsideTable, path)) return h;  // written before views set aside were kept
  h.set_aside.since_run_id = 1;
  if (HasTable(db, "stereorig_check_meta", path)) {
    Stmt since = Prepare(db, "SELECT rowid, value FROM stereorig_check_meta WHERE key = ?;", path);
    sqlite3_bind_text(since.get(), 1, kSetAsideSinceKey, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(since.get()) == SQLITE_ROW) {
      Row row(since.get(), path, "stereorig_check_meta");
      row.Within(kSetAsideSinceKey);
      // Kept as text ("12"): a TEXT column.
      const std::string text = row.String(1, "its value");
      const bool digits = !text.empty() && text.size() < 19 &&
                          std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!digits || std::stoll(text) < 1) row.Refuse("its value '" + text + "' is not a run id");
      h.set_aside.since_run_id = std::stoll(text);
    }
  }
  // A history from before edge-on views were set aside has no tilt_deg
  // column: its views were all set aside for other reasons (NULL).
  const bool tilts = HasColumn(db, kSetAsideTable, "tilt_deg", path);
  Stmt v = Prepare(db,
                   tilts ? "SELECT rowid, run_id, capture, camera, jump_rms_px, bound_px, tilt_deg FROM "
                           "stereorig_check_views_set_aside ORDER BY rowid;"
                         : "SELECT rowid, run_id, capture, camera, jump_rms_px, bound_px, NULL FROM "
                           "stereorig_check_views_set_aside ORDER BY rowid;",
                   path);
  while (sqlite3_step(v.get()) == SQLITE_ROW) {
    Row row(v.get(), path, kSetAsideTable);
    const HistoryRun& run = RunOf(row, by_id, row.Integer(1, "its run_id"));
    row.Within("run " + std::to_string(run.id));
    HistorySetAside view;
    view.run_id = run.id, view.date_utc = run.date_utc;
    view.capture = row.String(2, "its capture");
    const long long camera = row.Integer(3, "its camera");
    if (camera < 0 || camera > 1000000) row.Refuse("its camera " + std::to_string(camera) + " is no camera index");
    view.camera = static_cast<int>(camera);
    view.jump_rms_px = row.Number(4, "its jump_rms_px"), view.bound_px = row.Number(5, "its bound_px");
    if (view.jump_rms_px < 0 || view.bound_px < 0) row.Refuse("its jump_rms_px or bound_px is negative");
    view.tilt_deg = row.OptionalNumber(6, "its tilt_deg");
    if (view.tilt_deg && (*view.tilt_deg < 0 || *view.tilt_deg > 90))
      row.Refuse("its tilt_deg " + KSigmaText(*view.tilt_deg) + " is no tilt from face-on (0 to 90 deg)");
    h.set_aside.views.push_back(view);
  }
  std::stable_sort(h.set_aside.views.begin(), h.set_aside.views.end(),
                   [](const HistorySetAside& a, const HistorySetAside& b) {
                     return std::tie(a.run_id, a.camera, a.capture) < std::tie(b.run_id, b.camera, b.capture);
                   });
  return h;
}

// The first run of the same night (the same captures with the same rig
// file), if the history holds one. The history read (ReadHistory) first.
std::optional<HistoryRun> SameNight(const std::vector<HistoryRun>& runs, const HistoryRun& run) {
  if (run.captures_crc32.empty()) return std::nullopt;
  for (const HistoryRun& r : runs)  // oldest first
    if (r.captures_crc32 == run.captures_crc32 && r.rig_crc32 == run.rig_crc32) return r;
  return std::nullopt;
}

// `v` with `decimals` decimals below `fixed_below`, from there as %.4g: a
// threshold of 1e308 (finite, a corrupt row's) printed as 309 digits and
// broke the table.
std::string Bounded(double v, int decimals, double fixed_below = 1e6) {
  char text[48];
  if (std::fabs(v) < fixed_below)
    std::snprintf(text, sizeof text, "%.*f", decimals, v);
  else
    std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}
// A figure in the trend table's columns, 10 wide: 99999.9999 at most fixed.
std::string TableNumber(double v) { return Bounded(v, 4, 1e5); }

// a over b, a bound of 0 read as infinitely exceeded (not a division by 0).
double Ratio(double a, double b) { return b > 0 ? a / b : std::numeric_limits<double>::infinity(); }

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
    // Another program's database is refused; a history of ours is read
    // whole, every row checked: a night is not appended to a corrupt one.
    const std::vector<HistoryRun> runs =
        IsOurHistory(db.get(), path) ? ReadHistory(db.get(), path).runs : std::vector<HistoryRun>{};
    const bool kept_set_aside = HasTable(db.get(), kSetAsideTable, path);
    Exec(db.get(), kSchema, path);
    AddMissingColumns(db.get(), path);
    AllowRecaptureVerdict(db.get(), path);
    HistoryAppend outcome;
    outcome.same_night = SameNight(runs, run);
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
                         "INSERT INTO stereorig_check_views_set_aside (run_id, capture, camera, jump_rms_px, bound_px, "
                         "tilt_deg) VALUES (?, ?, ?, ?, ?, ?);",
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
      // NULL where set aside for another reason (bound every row: sqlite3_reset keeps the last one's).
      if (v.why == SetAsideWhy::kEdgeOn)
        sqlite3_bind_double(aside.get(), 6, v.tilt_deg);
      else
        sqlite3_bind_null(aside.get(), 6);
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
  return IsOurHistory(db.get(), path) ? ReadHistory(db.get(), path).runs : std::vector<HistoryRun>{};
}

std::vector<FigureTrend> ReadHistoryTrends(const std::string& path) {
  Db db = Open(path, false);
  return IsOurHistory(db.get(), path) ? ReadHistory(db.get(), path).trends : std::vector<FigureTrend>{};
}

HistorySetAsideLog ReadHistorySetAside(const std::string& path) {
  Db db = Open(path, false);
  return IsOurHistory(db.get(), path) ? ReadHistory(db.get(), path).set_aside : HistorySetAsideLog{};
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
  // Each threshold is its figure's expectation plus k_sigma of its standard
  // deviations: runs at another k failed (or passed) against other
  // thresholds, so the fails counted below are not one k's.
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
    out += t.name + std::string(t.name.size() < 40 ? 40 - t.name.size() : 0, ' ');  // a long name kept whole
    std::snprintf(line, sizeof line, " %5zu %10s %10s %10s %10s %10s %6d\n", t.points.size(),
                  TableNumber(t.points.front().value).c_str(), TableNumber(t.points.back().value).c_str(),
                  TableNumber(lo).c_str(), TableNumber(hi).c_str(), TableNumber(t.points.back().threshold).c_str(),
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
    // The worst against its bound among the views set aside for their
    // corners (jumps, another moment); those seen edge-on are counted apart:
    // set aside for the board's pose, their jumps within bound or not.
    const HistorySetAside* worst = nullptr;
    int edge_on = 0;
    double most_tilt_deg = 0;
    for (const HistorySetAside* v : views) {
      run_ids.insert(v->run_id);
      if (v->tilt_deg) {
        ++edge_on, most_tilt_deg = std::max(most_tilt_deg, *v->tilt_deg);
        continue;
      }
      if (!worst || Ratio(v->jump_rms_px, v->bound_px) > Ratio(worst->jump_rms_px, worst->bound_px)) worst = v;
    }
    std::snprintf(line, sizeof line, "views set aside: cam%d %zu view(s) on %zu of %zu run(s)", camera, views.size(),
                  run_ids.size(), kept_runs);
    out += line + since;
    std::snprintf(line, sizeof line, ", last run %lld (", views.back()->run_id);
    out += line + views.back()->date_utc + ")";
    if (edge_on > 0) {
      std::snprintf(line, sizeof line, "; %d seen edge-on (up to %.0f deg from face-on)", edge_on, most_tilt_deg);
      out += line;
    }
    if (worst) {
      std::snprintf(line, sizeof line, "; the worst against its bound: %s px, %sx its %s px (capture ",
                    Bounded(worst->jump_rms_px, 3).c_str(),
                    Bounded(Ratio(worst->jump_rms_px, worst->bound_px), 1).c_str(),
                    Bounded(worst->bound_px, 3).c_str());
      out += line + worst->capture + ", run " + std::to_string(worst->run_id) + ")";
    }
    out += "\n";
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
      out += Bounded(w->second.ratio, 2) + "x " + w->second.name;
    }
    if (r.verdict != "ok") out += "; " + r.explanation;
    out += "\n";
  }
  return out;
}

}  // namespace stereorig
