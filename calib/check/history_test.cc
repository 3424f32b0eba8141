#include "calib/check/history.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

CheckResult Result(double value, bool pass) {
  CheckResult r;
  r.figures = {{"cam0_consistency_rms_px", value, 0.25, pass, 700}, {"pair_0_1_closure_mm", value / 10, 0.02, true, 8}};
  if (!pass) {
    CameraChange moved;
    moved.camera = 0;
    moved.kind = CameraChangeKind::kMoved;
    moved.turned_deg = 0.05, moved.shifted_mm = 0.002;
    r.camera_changes = {moved};
  }
  return r;
}

// A history as an older version wrote it: the runs and figures tables
// alone, then `sql` (more tables, rows). True when it was made.
bool MakeOldHistory(const std::string& path, const std::string& sql) {
  sqlite3* raw = nullptr;
  const bool opened = sqlite3_open(path.c_str(), &raw) == SQLITE_OK;
  const std::string all =
      "CREATE TABLE stereorig_check_runs (id INTEGER PRIMARY KEY AUTOINCREMENT, date_utc TEXT NOT NULL, rig_file TEXT "
      "NOT NULL, captures TEXT NOT NULL, verdict TEXT NOT NULL, explanation TEXT NOT NULL);"
      "CREATE TABLE stereorig_check_figures (run_id INTEGER NOT NULL, name TEXT NOT NULL, value REAL NOT NULL, "
      "threshold REAL NOT NULL, pass INTEGER NOT NULL, samples INTEGER NOT NULL);" +
      sql;
  const bool made = opened && sqlite3_exec(raw, all.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK;
  sqlite3_close(raw);
  return made;
}

TEST(History, AppendsRunsAndReadsTrendsBack) {
  const std::string db = ::testing::TempDir() + "/history_test.sqlite";
  std::filesystem::remove(db);
  AppendToHistory(db, {0, "2026-11-20T02:00:00Z", "rig.yaml", "night1", "", ""}, Result(0.20, true));
  AppendToHistory(db, {0, "2026-11-21T02:00:00Z", "rig.yaml", "night2", "", ""}, Result(0.21, true));
  AppendToHistory(db, {0, "2026-11-22T02:00:00Z", "rig.yaml", "night3", "", ""}, Result(0.90, false));
  const auto runs = ReadHistoryRuns(db);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(runs[2].verdict, "recalibrate");
  EXPECT_EQ(runs[2].explanation, "camera 0 moved: turned 0.050 deg, shifted 0.002 mm");
  const auto trends = ReadHistoryTrends(db);
  ASSERT_EQ(trends.size(), 2u);
  EXPECT_EQ(trends[0].name, "cam0_consistency_rms_px");
  ASSERT_EQ(trends[0].points.size(), 3u);
  EXPECT_DOUBLE_EQ(trends[0].points[1].value, 0.21);
  EXPECT_FALSE(trends[0].points[2].pass);
  const std::string table = FormatTrends(runs, trends);
  EXPECT_NE(table.find("cam0_consistency_rms_px"), std::string::npos);
  EXPECT_NE(table.find("3 run(s)"), std::string::npos);
}

// Each run keeps what it was measured with, so a trend across a
// recalibration written to the same path is not read as one rig's (a user's
// walkthrough merged two rig files' runs into one trend, unsaid).
TEST(History, KeepsTheRigFileEachRunUsedAndSaysWhenItChanged) {
  const std::string db = ::testing::TempDir() + "/history_inputs.sqlite";
  std::filesystem::remove(db);
  auto run = [](const char* date, const char* crc) {
    HistoryRun r{0, date, "rig.yaml", "night", "", ""};
    r.rig_path = "/line/rig.yaml", r.rig_crc32 = crc, r.target_path = "/line/target.yaml", r.board = "as calibrated";
    return r;
  };
  AppendToHistory(db, run("2026-11-20T02:00:00Z", "0badc0de"), Result(0.20, true));
  AppendToHistory(db, run("2026-11-21T02:00:00Z", "0badc0de"), Result(0.21, true));
  AppendToHistory(db, run("2026-11-22T02:00:00Z", "12345678"), Result(0.20, true));
  const auto runs = ReadHistoryRuns(db);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(runs[0].rig_path, "/line/rig.yaml");
  EXPECT_EQ(runs[2].rig_crc32, "12345678");
  EXPECT_EQ(runs[1].target_path, "/line/target.yaml");
  EXPECT_EQ(runs[1].board, "as calibrated");
  const std::string table = FormatTrends(runs, ReadHistoryTrends(db));
  EXPECT_NE(table.find("rig files: 2 different ones"), std::string::npos) << table;
  EXPECT_NE(table.find("runs 1..2: /line/rig.yaml (crc32 0badc0de"), std::string::npos) << table;
  EXPECT_NE(table.find("runs 3..3: /line/rig.yaml (crc32 12345678"), std::string::npos) << table;
  // One rig file throughout: nothing said.
  std::vector<HistoryRun> same(runs.begin(), runs.begin() + 2);
  EXPECT_EQ(FormatTrends(same, ReadHistoryTrends(db)).find("rig files:"), std::string::npos);
}

// The rig file as the history keeps it: one path per file, absolute and
// canonical, in the runs table as in the inputs table. It was kept as typed
// ("rig.yaml", "../line/rig.yaml"), relative to a folder the history does
// not record, beside the inputs table's absolute path: the same file under
// two names in one run. A history written so is still read, each such
// run's rig file taken from its inputs row (the same run made it absolute).
TEST(History, KeepsTheRigFileAbsoluteAndCanonicalAndReadsOlderRunsAsTyped) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::absolute(::testing::TempDir()) / "history_paths";
  fs::remove_all(dir);
  fs::create_directories(dir / "line");
  fs::create_directories(dir / "other");
  std::ofstream(dir / "line" / "rig.yaml") << "format: stereorig-rig\n";
  fs::create_symlink(dir / "line" / "rig.yaml", dir / "current-rig.yaml");
  const std::string rig = fs::canonical(dir / "line" / "rig.yaml").string();
  const std::string db = (dir / "history.sqlite").string();
  // Typed three ways, from the test's folder: relative, through "..", and
  // through a link. One path kept, in both tables.
  for (const fs::path& typed : {fs::relative(dir / "line" / "rig.yaml"), dir / "other" / ".." / "line" / "rig.yaml",
                                dir / "current-rig.yaml"}) {
    HistoryRun r{0, "2026-11-20T02:00:00Z", typed.string(), "night", "", ""};
    r.rig_path = typed.string(), r.rig_crc32 = "0badc0de", r.target_path = typed.string();
    AppendToHistory(db, r, Result(0.20, true));
  }
  const auto runs = ReadHistoryRuns(db);
  ASSERT_EQ(runs.size(), 3u);
  for (const HistoryRun& r : runs) {
    EXPECT_EQ(r.rig_file, rig) << "run " << r.id;
    EXPECT_EQ(r.rig_path, rig) << "run " << r.id;
    EXPECT_EQ(r.target_path, rig) << "run " << r.id;
  }
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
    sqlite3_stmt* s = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(raw, "SELECT rig_file FROM stereorig_check_runs;", -1, &s, nullptr), SQLITE_OK);
    while (sqlite3_step(s) == SQLITE_ROW) EXPECT_EQ(reinterpret_cast<const char*>(sqlite3_column_text(s, 0)), rig);
    sqlite3_finalize(s);
    sqlite3_close(raw);
  }

  // Older histories: a run with an inputs row and rig_file as typed reads
  // its rig_path; a run from before the inputs were kept reads as typed
  // (nothing says from which folder); both are still read, and appended to.
  const std::string old_db = (dir / "old.sqlite").string();
  ASSERT_TRUE(
      MakeOldHistory(old_db,
                     "CREATE TABLE stereorig_check_run_inputs (run_id INTEGER NOT NULL, rig_path TEXT NOT NULL, "
                     "rig_crc32 TEXT NOT NULL, target_path TEXT NOT NULL, board TEXT NOT NULL);"
                     "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                     "VALUES ('2026-11-01T02:00:00Z', 'rig.yaml', 'n1', 'ok', 'every figure within its "
                     "threshold');"
                     "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                     "VALUES ('2026-11-02T02:00:00Z', '../line/rig.yaml', 'n2', 'ok', 'every figure within its "
                     "threshold');"
                     "INSERT INTO stereorig_check_run_inputs VALUES (2, '/line/rig.yaml', '0badc0de', "
                     "'/line/target.yaml', 'as calibrated');"));
  HistoryRun next{0, "2026-11-03T02:00:00Z", rig, "n3", "", ""};
  next.rig_path = rig;
  AppendToHistory(old_db, next, Result(0.20, true));
  const auto old_runs = ReadHistoryRuns(old_db);
  ASSERT_EQ(old_runs.size(), 3u);
  EXPECT_EQ(old_runs[0].rig_file, "rig.yaml");  // no inputs row: as typed
  EXPECT_EQ(old_runs[0].captures, "n1");        // as typed, as written
  EXPECT_EQ(old_runs[1].rig_file, "/line/rig.yaml");
  EXPECT_EQ(old_runs[1].rig_path, "/line/rig.yaml");
  EXPECT_EQ(old_runs[2].rig_file, rig);
  EXPECT_NE(FormatTrends(old_runs, ReadHistoryTrends(old_db)).find("3 run(s)"), std::string::npos);
}

// The captures folder is kept as the rig file is (HistoryPathOf): it was
// kept as typed, relative to a folder the history does not record, so one
// folder read as many. A path that is not a regular file (a folder, or
// one not there) is resolved through the part that exists: lexically
// normal, "link/../x" read as the folder holding the link, where the link
// names a folder elsewhere. Older runs' captures read back as typed.
TEST(History, KeepsTheCapturesFolderAbsoluteAndResolvesPathsThroughLinks) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::absolute(::testing::TempDir()) / "history_captures";
  fs::remove_all(dir);
  fs::create_directories(dir / "line" / "nights" / "tonight");
  fs::create_symlink(dir / "line" / "nights", dir / "nights");
  const std::string nights = fs::canonical(dir / "line" / "nights").string();
  // Through the link and "..": the folder the link names is in line/.
  EXPECT_EQ(HistoryPathOf((dir / "nights" / ".." / "nights" / "tonight").string()), nights + "/tonight");
  EXPECT_EQ(HistoryPathOf((dir / "nights" / ".." / "not-there.yaml").string()),
            fs::canonical(dir / "line").string() + "/not-there.yaml");
  const std::string db = (dir / "history.sqlite").string();
  HistoryRun r{0, "2026-11-20T02:00:00Z", "rig.yaml", (dir / "nights" / "." / "tonight").string(), "", ""};
  AppendToHistory(db, r, Result(0.20, true));
  const auto runs = ReadHistoryRuns(db);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].captures, nights + "/tonight");
}

// A history the night cannot be written to is found before the check's
// work: here another process holds it (a write lock), the case a test run
// as root can make (root writes a read-only file; the read-only file and
// folder were tried as user nobody). A writable one passes and is left as
// it was: the probe's table is rolled back.
TEST(History, AHistoryThatCannotBeWrittenIsFoundBeforeTheNight) {
  const std::string db = ::testing::TempDir() + "/history_writable.sqlite";
  std::filesystem::remove(db);
  AppendToHistory(db, {0, "2026-11-20T02:00:00Z", "rig.yaml", "night1", "", ""}, Result(0.20, true));
  EXPECT_NO_THROW(RequireHistoryWritable(db));
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &other), SQLITE_OK);
  auto tables = [&] {
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(other, "SELECT count(*) FROM sqlite_master WHERE type = 'table';", -1, &s, nullptr);
    sqlite3_step(s);
    const int n = sqlite3_column_int(s, 0);
    sqlite3_finalize(s);
    return n;
  };
  const int before = tables();
  EXPECT_NO_THROW(RequireHistoryWritable(db));
  EXPECT_EQ(tables(), before);
  ASSERT_EQ(sqlite3_exec(other, "BEGIN IMMEDIATE;", nullptr, nullptr, nullptr), SQLITE_OK);  // the other process
  try {
    RequireHistoryWritable(db);
    ADD_FAILURE() << "a history another process holds passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be written"), std::string::npos) << e.what();
    EXPECT_EQ(e.where(), db);
  }
  sqlite3_exec(other, "ROLLBACK;", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  EXPECT_EQ(ReadHistoryRuns(db).size(), 1u);
}

// The views a run set aside are kept with it, so a camera that loses views
// night after night shows in the history, not only in each night's report.
TEST(History, KeepsTheViewsSetAsideAndCountsThemPerCamera) {
  const std::string db = ::testing::TempDir() + "/history_set_aside.sqlite";
  std::filesystem::remove(db);
  CheckResult night1 = Result(0.20, true), night2 = Result(0.21, true), night3 = Result(0.22, true);
  night1.views_set_aside = {{3, 1, 0.52, 0.06}};
  // Camera 2 before camera 1, as a run may list them; camera 1's second view
  // jumps further (0.90 px) but is less far beyond its bound (1.8x, against
  // the first night's 8.7x).
  night3.views_set_aside = {{2, 2, 0.09, 0.07}, {7, 1, 0.90, 0.50}};
  AppendToHistory(db, {0, "2026-11-20T02:00:00Z", "rig.yaml", "night1", "", ""}, night1, {{3, "0003"}});
  AppendToHistory(db, {0, "2026-11-21T02:00:00Z", "rig.yaml", "night2", "", ""}, night2);
  AppendToHistory(db, {0, "2026-11-22T02:00:00Z", "rig.yaml", "night3", "", ""}, night3, {{7, "0007"}});
  const HistorySetAsideLog aside = ReadHistorySetAside(db);
  EXPECT_EQ(aside.since_run_id, 1);  // a new database keeps them from its first run
  ASSERT_EQ(aside.views.size(), 3u);
  EXPECT_EQ(aside.views[0].run_id, 1);
  EXPECT_EQ(aside.views[0].capture, "0003");
  EXPECT_EQ(aside.views[0].camera, 1);
  EXPECT_DOUBLE_EQ(aside.views[0].jump_rms_px, 0.52);
  EXPECT_DOUBLE_EQ(aside.views[0].bound_px, 0.06);
  EXPECT_EQ(aside.views[0].date_utc, "2026-11-20T02:00:00Z");
  EXPECT_EQ(aside.views[1].run_id, 3);  // run 3, cameras in order, though given camera 2 first
  EXPECT_EQ(aside.views[1].camera, 1);
  EXPECT_EQ(aside.views[1].capture, "0007");
  EXPECT_EQ(aside.views[2].camera, 2);
  EXPECT_EQ(aside.views[2].capture, "2");  // no name given: its index
  const std::string table = FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), aside);
  EXPECT_NE(table.find("views set aside: cam1 2 view(s) on 2 of 3 run(s), last run 3 (2026-11-22T02:00:00Z); the "
                       "worst against its bound: 0.520 px, 8.7x its 0.060 px (capture 0003, run 1)"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("views set aside: cam2 1 view(s) on 1 of 3 run(s), last run 3"), std::string::npos) << table;
  EXPECT_EQ(table.find("cam0 "), std::string::npos) << table;  // none of camera 0's
  HistorySetAsideLog none = aside;
  none.views.clear();
  EXPECT_NE(FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), none).find("views set aside: none in 3 run(s)\n"),
            std::string::npos);
}

// A database written before views set aside were kept has no such table:
// read as not kept, and the next append adds it, counting from that run
// only (the earlier runs set views aside too, unrecorded).
TEST(History, CountsTheViewsSetAsideOnlySinceTheRunThatFirstKeptThem) {
  const std::string db = ::testing::TempDir() + "/history_old.sqlite";
  std::filesystem::remove(db);
  ASSERT_TRUE(MakeOldHistory(db,
                             "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                             "VALUES ('2026-11-01T02:00:00Z', 'rig.yaml', 'old', 'ok', 'every figure within its "
                             "threshold');"));
  const HistorySetAsideLog before = ReadHistorySetAside(db);
  EXPECT_EQ(before.since_run_id, 0);
  EXPECT_TRUE(before.views.empty());
  EXPECT_NE(FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), before).find("views set aside: not kept"),
            std::string::npos);
  CheckResult night = Result(0.2, true);
  night.views_set_aside = {{1, 0, 0.4, 0.05}};
  AppendToHistory(db, {0, "2026-11-02T02:00:00Z", "rig.yaml", "new", "", ""}, night);
  AppendToHistory(db, {0, "2026-11-03T02:00:00Z", "rig.yaml", "newer", "", ""}, Result(0.2, true));
  const HistorySetAsideLog after = ReadHistorySetAside(db);
  EXPECT_EQ(after.since_run_id, 2);  // not moved by the later append
  ASSERT_EQ(after.views.size(), 1u);
  EXPECT_EQ(after.views[0].run_id, 2);
  EXPECT_EQ(ReadHistoryRuns(db).size(), 3u);
  EXPECT_NE(
      FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), after)
          .find("views set aside: cam0 1 view(s) on 1 of 2 run(s) since run 2 (2026-11-02T02:00:00Z), last run 2"),
      std::string::npos)
      << FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), after);
}

// A view set aside as seen edge-on keeps its tilt (tilt_deg) beside its
// jump figure, which did not set it aside, so its camera's line counts it
// apart and takes the worst against its bound over the others. A history
// whose views-set-aside table is from before (no tilt_deg) still reads,
// every earlier view NULL (none was set aside for its tilt), and gets the
// column at its next append.
TEST(History, KeepsTheTiltOfAViewSetAsideAsSeenEdgeOnAndReadsAnOlderTableWithout) {
  const std::string db = ::testing::TempDir() + "/history_edge_on.sqlite";
  std::filesystem::remove(db);
  ASSERT_TRUE(MakeOldHistory(db,
                             "CREATE TABLE stereorig_check_views_set_aside (run_id INTEGER NOT NULL, capture TEXT NOT "
                             "NULL, camera INTEGER NOT NULL, jump_rms_px REAL NOT NULL, bound_px REAL NOT NULL);"
                             "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                             "VALUES ('2026-11-01T02:00:00Z', 'rig.yaml', 'old', 'ok', 'every figure within its "
                             "threshold');"
                             "INSERT INTO stereorig_check_views_set_aside VALUES (1, '0002', 5, 0.52, 0.06);"));
  HistorySetAsideLog before = ReadHistorySetAside(db);
  ASSERT_EQ(before.views.size(), 1u);
  EXPECT_FALSE(before.views[0].tilt_deg);
  CheckResult night = Result(0.2, true);
  SetAsideView edge_on{6, 5, 0.040, 0.061};
  edge_on.why = SetAsideWhy::kEdgeOn, edge_on.tilt_deg = 80.4;
  night.views_set_aside = {edge_on, {7, 5, 0.30, 0.06}};
  AppendToHistory(db, {0, "2026-11-02T02:00:00Z", "rig.yaml", "new", "", ""}, night, {{6, "006"}, {7, "007"}});
  const HistorySetAsideLog after = ReadHistorySetAside(db);
  ASSERT_EQ(after.views.size(), 3u);
  EXPECT_FALSE(after.views[0].tilt_deg);  // the older run's
  EXPECT_EQ(after.views[1].capture, "006");
  ASSERT_TRUE(after.views[1].tilt_deg);
  EXPECT_DOUBLE_EQ(*after.views[1].tilt_deg, 80.4);
  EXPECT_DOUBLE_EQ(after.views[1].jump_rms_px, 0.040);
  EXPECT_FALSE(after.views[2].tilt_deg);  // a jump, in the same run
  const std::string table = FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), after);
  EXPECT_NE(table.find("views set aside: cam5 3 view(s) on 2 of 2 run(s), last run 2 (2026-11-02T02:00:00Z); 1 seen "
                       "edge-on (up to 80 deg from face-on); the worst against its bound: 0.520 px, 8.7x its 0.060 px "
                       "(capture 0002, run 1)"),
            std::string::npos)
      << table;
  // A camera whose views went for their tilt alone has no worst to give.
  HistorySetAsideLog only_edge_on = after;
  only_edge_on.views = {after.views[1]};
  EXPECT_NE(FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), only_edge_on)
                .find("views set aside: cam5 1 view(s) on 1 of 2 run(s), last run 2 (2026-11-02T02:00:00Z); 1 seen "
                      "edge-on (up to 80 deg from face-on)\n"),
            std::string::npos)
      << FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), only_edge_on);
}

// A capture's name of any length is kept whole on its line.
TEST(History, KeepsALongCaptureNameWhole) {
  const std::string db = ::testing::TempDir() + "/history_long_name.sqlite";
  std::filesystem::remove(db);
  const std::string name(300, 'n');
  CheckResult night = Result(0.2, true);
  night.views_set_aside = {{4, 3, 0.4, 0.05}};
  AppendToHistory(db, {0, "2026-11-02T02:00:00Z", "rig.yaml", "c", "", ""}, night, {{4, name}});
  const std::string table = FormatTrends(ReadHistoryRuns(db), ReadHistoryTrends(db), ReadHistorySetAside(db));
  EXPECT_NE(table.find("(capture " + name + ", run 1)\n"), std::string::npos) << table;
}

TEST(History, RejectsAFileThatIsNotADatabaseAndLeavesItAlone) {
  const std::string path = ::testing::TempDir() + "/not_a_db.sqlite";
  { std::ofstream(path) << "this is a text file, not SQLite\n"; }
  EXPECT_THROW(AppendToHistory(path, {0, "d", "r", "c", "", ""}, Result(0.2, true)), InputError);
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "this is a text file, not SQLite");
  EXPECT_THROW(ReadHistoryRuns(::testing::TempDir() + "/missing.sqlite"), InputError);
}

// An empty file (provisioned for a service user with `install -m 664
// /dev/null`) is an empty database: no runs, and the first append makes it
// ours. Another program's database is refused, and left as it was.
TEST(History, AnEmptyFileIsAnEmptyHistoryAndAnotherDatabaseIsRefused) {
  const std::string db = ::testing::TempDir() + "/history_empty.sqlite";
  std::filesystem::remove(db);
  { std::ofstream(db, std::ios::binary); }
  EXPECT_TRUE(ReadHistoryRuns(db).empty());
  EXPECT_TRUE(ReadHistoryTrends(db).empty());
  EXPECT_TRUE(ReadHistorySetAside(db).views.empty());
  EXPECT_EQ(std::filesystem::file_size(db), 0u);  // reading writes nothing
  EXPECT_NO_THROW(RequireHistoryWritable(db));
  EXPECT_EQ(AppendToHistory(db, {0, "2026-11-20T02:00:00Z", "rig.yaml", "night1", "", ""}, Result(0.2, true)).run_id,
            1);
  EXPECT_EQ(ReadHistoryRuns(db).size(), 1u);
  EXPECT_EQ(ReadHistorySetAside(db).since_run_id, 1);

  const std::string foreign = ::testing::TempDir() + "/history_foreign.sqlite";
  std::filesystem::remove(foreign);
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(foreign.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw, "CREATE TABLE parts (id INTEGER);", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(raw);
  const auto size = std::filesystem::file_size(foreign);
  for (int reader = 0; reader < 2; ++reader) {
    try {
      if (reader == 0)
        ReadHistoryRuns(foreign);
      else
        AppendToHistory(foreign, {0, "d", "r", "c", "", ""}, Result(0.2, true));
      ADD_FAILURE() << "another program's database was taken";
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), foreign);
      EXPECT_EQ(e.problem(),
                "an SQLite database, but not a stereorig check history (it has no table stereorig_check_runs): give "
                "another with --history-db");
    }
  }
  EXPECT_EQ(std::filesystem::file_size(foreign), size);
}

// k_sigma and the captures' CRC are columns added to
// stereorig_check_run_inputs after it was first written: a history from
// before gets them at its next append, its earlier runs reading unknown,
// and the trend says the runs were not all at one k.
TEST(History, KeepsKSigmaAndAddsItsColumnToAnOlderHistory) {
  const std::string db = ::testing::TempDir() + "/history_k.sqlite";
  std::filesystem::remove(db);
  ASSERT_TRUE(MakeOldHistory(db,
                             "CREATE TABLE stereorig_check_run_inputs (run_id INTEGER NOT NULL, rig_path TEXT NOT "
                             "NULL, rig_crc32 TEXT NOT NULL, target_path TEXT NOT NULL, board TEXT NOT NULL);"
                             "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                             "VALUES ('2026-11-01T02:00:00Z', '/r.yaml', '/old', 'ok', 'every figure within its "
                             "threshold');"
                             "INSERT INTO stereorig_check_run_inputs VALUES (1, '/r.yaml', '0000abcd', '/t.yaml', "
                             "'as calibrated');"));
  ASSERT_EQ(ReadHistoryRuns(db).size(), 1u);  // read before the columns exist
  EXPECT_FALSE(ReadHistoryRuns(db)[0].k_sigma);
  HistoryRun run{0, "2026-11-02T02:00:00Z", "/r.yaml", "/new", "", ""};
  run.rig_crc32 = "0000abcd", run.k_sigma = 2.5, run.captures_crc32 = "12345678";
  EXPECT_EQ(AppendToHistory(db, run, Result(0.2, true)).run_id, 2);
  const auto runs = ReadHistoryRuns(db);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_FALSE(runs[0].k_sigma);
  EXPECT_EQ(runs[0].captures_crc32, "");
  ASSERT_TRUE(runs[1].k_sigma);
  EXPECT_EQ(*runs[1].k_sigma, 2.5);
  EXPECT_EQ(runs[1].captures_crc32, "12345678");
  EXPECT_NE(FormatTrends(runs, ReadHistoryTrends(db))
                .find("k_sigma varied over these runs (each run's thresholds and fails are at its own k): 2.5 in "
                      "run(s) 2; unknown (written before it was kept) in run(s) 1\n"),
            std::string::npos)
      << FormatTrends(runs, ReadHistoryTrends(db));
  EXPECT_NE(FormatTrends({runs[1]}, {}).find("k_sigma: 2.5 in every run\n"), std::string::npos);
}

// A history from before the verdict recapture has its runs table rebuilt
// at the next append (SQLite cannot alter a CHECK). What a plant added to
// that table, an index and a trigger raising an alert on a verdict not ok,
// went with the old table, silently, and the AUTOINCREMENT counter restarted
// at the largest id kept: a deleted last run's id was given again.
TEST(History, TheRebuildForRecaptureKeepsAPlantsTriggerIndexAndRunIds) {
  const std::string db = ::testing::TempDir() + "/history_rebuild.sqlite";
  std::filesystem::remove(db);
  ASSERT_TRUE(MakeOldHistory(
      db,
      "CREATE TABLE plant_alerts (run_id INTEGER, verdict TEXT);"
      "CREATE INDEX plant_runs_by_date ON stereorig_check_runs (date_utc);"
      "CREATE TRIGGER plant_alert AFTER INSERT ON stereorig_check_runs WHEN NEW.verdict <> 'ok' BEGIN INSERT INTO "
      "plant_alerts VALUES (NEW.id, NEW.verdict); END;"
      "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) VALUES "
      "('2026-11-01T02:00:00Z', '/r.yaml', '/n1', 'ok', 'every figure within its threshold'),"
      "('2026-11-02T02:00:00Z', '/r.yaml', '/n2', 'ok', 'every figure within its threshold'),"
      "('2026-11-03T02:00:00Z', '/r.yaml', '/n3', 'ok', 'every figure within its threshold');"
      "DELETE FROM stereorig_check_runs WHERE id = 3;"));
  EXPECT_EQ(AppendToHistory(db, {0, "2026-11-04T02:00:00Z", "/r.yaml", "/n4", "", ""}, Result(0.3, false)).run_id, 4);
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
  auto count = [&](const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    int n = -1;
    if (sqlite3_prepare_v2(raw, sql.c_str(), -1, &s, nullptr) == SQLITE_OK && sqlite3_step(s) == SQLITE_ROW)
      n = sqlite3_column_int(s, 0);
    sqlite3_finalize(s);
    return n;
  };
  EXPECT_EQ(count("SELECT count(*) FROM sqlite_master WHERE sql LIKE '%''recapture''%' AND name = "
                  "'stereorig_check_runs'"),
            1);  // rebuilt
  EXPECT_EQ(count("SELECT count(*) FROM sqlite_master WHERE name IN ('plant_runs_by_date', 'plant_alert') AND "
                  "tbl_name = 'stereorig_check_runs'"),
            2);
  EXPECT_EQ(count("SELECT count(*) FROM plant_alerts WHERE run_id = 4 AND verdict = 'recalibrate'"), 1);
  sqlite3_close(raw);
  EXPECT_EQ(ReadHistoryRuns(db).size(), 3u);
}

// The same captures with the same rig file a second time: not appended,
// the outcome naming the run it repeats; what before_commit throws rolls the
// run back.
TEST(History, TheSameNightIsNotAppendedTwice) {
  const std::string db = ::testing::TempDir() + "/history_twice.sqlite";
  std::filesystem::remove(db);
  HistoryRun run{0, "2026-11-02T02:00:00Z", "/r.yaml", "/night", "", ""};
  run.rig_crc32 = "0000abcd", run.captures_crc32 = "12345678", run.k_sigma = 3.5;
  EXPECT_EQ(AppendToHistory(db, run, Result(0.9, false)).run_id, 1);
  HistoryAppend seen;
  const HistoryAppend again =
      AppendToHistory(db, run, Result(0.9, false), {}, [&](const HistoryAppend& a) { seen = a; });
  EXPECT_EQ(again.run_id, 0);
  ASSERT_TRUE(again.same_night && seen.same_night);
  EXPECT_EQ(again.same_night->id, 1);
  EXPECT_EQ(seen.same_night->id, 1);
  EXPECT_EQ(again.same_night->verdict, "recalibrate");
  EXPECT_EQ(again.same_night->date_utc, "2026-11-02T02:00:00Z");
  EXPECT_EQ(ReadHistoryRuns(db).size(), 1u);
  HistoryRun other_rig = run, other_night = run;
  other_rig.rig_crc32 = "0000abce";  // recalibrated: the same captures are another check
  other_night.captures_crc32 = "12345679";
  EXPECT_EQ(AppendToHistory(db, other_rig, Result(0.2, true)).run_id, 2);
  EXPECT_THROW(AppendToHistory(db, other_night, Result(0.2, true), {},
                               [](const HistoryAppend&) { throw InputError("report.json", "cannot be written"); }),
               InputError);
  EXPECT_EQ(ReadHistoryRuns(db).size(), 2u);  // rolled back
  EXPECT_EQ(AppendToHistory(db, other_night, Result(0.2, true)).run_id, 3);
}

// One run a line, the last N: date, k, verdict, fails, the figure nearest
// its threshold, and why where not ok.
TEST(History, ListsTheLastRunsOneALine) {
  const std::string db = ::testing::TempDir() + "/history_series.sqlite";
  std::filesystem::remove(db);
  HistoryRun run{0, "2026-11-01T02:00:00Z", "/r.yaml", "/n", "", ""};
  run.k_sigma = 3.5;
  AppendToHistory(db, run, Result(0.20, true));
  run.date_utc = "2026-11-02T02:00:00Z";
  AppendToHistory(db, run, Result(0.21, true));
  run.date_utc = "2026-11-03T02:00:00Z";
  AppendToHistory(db, run, Result(0.90, false));
  const std::string series = FormatRunSeries(ReadHistoryRuns(db), ReadHistoryTrends(db), 2);
  // Run 2's nearest is the closure's 0.021 mm against 0.02 mm (1.05x, passed
  // as Result() sets it), not cam0's 0.21 px against 0.25 px (0.84x).
  EXPECT_EQ(
      series,
      "runs (the last 2):\n"
      "   run  date_utc              k_sigma  verdict      fails  nearest its threshold (value / threshold); why, "
      "where not ok\n"
      "     2  2026-11-02T02:00:00Z      3.5  ok               0  1.05x pair_0_1_closure_mm\n"
      "     3  2026-11-03T02:00:00Z      3.5  recalibrate      1  4.50x pair_0_1_closure_mm; camera 0 moved: "
      "turned 0.050 deg, shifted 0.002 mm\n");
}

// Every row is checked as it is read: SQLite keeps whatever a column is
// given (a REAL column keeps 'abc' as text; a table made by hand has no NOT
// NULL), and read unchecked a corrupt row was a figure of 0.0000, a nameless
// figure, a verdict 'banana', a run that is not there, with exit 0, and a
// night appended to it all the same. Now each read, and the append, refuses
// naming the database, the table, the row and what is wrong, and the file
// is left as it was. The histories are made as an older version wrote them
// (no CHECKs: a new history's refuse such rows, NewTablesRefuse... below).
TEST(History, ABadRowIsRefusedNamingTheTableTheRowAndWhatIsWrong) {
  const std::string good_runs =
      "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) VALUES "
      "('2026-11-01T02:00:00Z', '/r.yaml', '/n1', 'ok', 'every figure within its threshold'),"
      "('2026-11-02T02:00:00Z', '/r.yaml', '/n2', 'ok', 'every figure within its threshold');"
      "INSERT INTO stereorig_check_figures VALUES (1, 'cam0_x', 0.2, 0.25, 1, 700), (2, 'cam0_x', 0.21, 0.25, 1, 700);";
  // The figures table made again by hand, without NOT NULL (as a walkthrough
  // found one): it takes NULLs.
  const std::string loose_figures =
      "CREATE TABLE loose (run_id INTEGER, name TEXT, value REAL, threshold REAL, pass INTEGER, samples INTEGER);"
      "INSERT INTO loose SELECT * FROM stereorig_check_figures; DROP TABLE stereorig_check_figures;"
      "ALTER TABLE loose RENAME TO stereorig_check_figures;";
  struct Case {
    std::string sql, problem;
  };
  const std::vector<Case> cases = {
      {"INSERT INTO stereorig_check_figures VALUES (2, 'cam1_x', 'abc', 0.25, 1, 700);",
       "stereorig_check_figures row 3 (run 2): the value of figure cam1_x is 'abc', not a number"},
      {"INSERT INTO stereorig_check_figures VALUES (2, 'cam1_x', 0.2, 9e999, 1, 700);",
       "stereorig_check_figures row 3 (run 2): the threshold of figure cam1_x is inf, not a finite number"},
      {loose_figures + "INSERT INTO stereorig_check_figures VALUES (2, NULL, 0.2, 0.25, 1, 700);",
       "stereorig_check_figures row 3 (run 2): its name is NULL, not text"},
      {loose_figures + "INSERT INTO stereorig_check_figures VALUES (2, 'cam1_x', NULL, 0.25, 1, 700);",
       "stereorig_check_figures row 3 (run 2): the value of figure cam1_x is NULL, not a number"},
      {"INSERT INTO stereorig_check_figures VALUES (2, 'cam1_x', 0.2, 0.25, 7, 700);",
       "stereorig_check_figures row 3 (run 2): the pass of figure cam1_x is 7, not 0 or 1"},
      {"INSERT INTO stereorig_check_figures VALUES (9999, 'orphan', 1.0, 1.0, 1, 1);",
       "stereorig_check_figures row 3: its run_id 9999 names no run in stereorig_check_runs"},
      {"INSERT INTO stereorig_check_figures VALUES (2, 'cam0_x', 0.2, 0.25, 1, 700);",
       "stereorig_check_figures row 3 (run 2): figure cam0_x a second time in its run (row 2 is the first"},
      {"UPDATE stereorig_check_runs SET verdict = 'banana' WHERE id = 2;",
       "stereorig_check_runs row 2 (run 2): its verdict 'banana' is neither ok, recalibrate nor recapture"},
      {"UPDATE stereorig_check_runs SET date_utc = X'FF00' WHERE id = 2;",
       "stereorig_check_runs row 2 (run 2): its date_utc is a blob of 2 bytes, not text"},
      {"CREATE TABLE stereorig_check_run_inputs (run_id INTEGER, rig_path TEXT, rig_crc32 TEXT, target_path TEXT, "
       "board TEXT, k_sigma REAL); INSERT INTO stereorig_check_run_inputs VALUES (2, '/r.yaml', '0badc0de', "
       "'/t.yaml', 'as calibrated', -3);",
       "stereorig_check_run_inputs row 1 (run 2): its k_sigma -3 is not positive"},
      {"CREATE TABLE stereorig_check_views_set_aside (run_id INTEGER, capture TEXT, camera INTEGER, jump_rms_px "
       "REAL, bound_px REAL); INSERT INTO stereorig_check_views_set_aside VALUES (2, '003', 'one', 0.4, 0.05);",
       "stereorig_check_views_set_aside row 1 (run 2): its camera is 'one', not an integer"},
      {"CREATE TABLE stereorig_check_views_set_aside (run_id INTEGER, capture TEXT, camera INTEGER, jump_rms_px "
       "REAL, bound_px REAL, tilt_deg REAL); INSERT INTO stereorig_check_views_set_aside VALUES (2, '006', 5, 0.04, "
       "0.06, 95);",
       "stereorig_check_views_set_aside row 1 (run 2): its tilt_deg 95 is no tilt from face-on (0 to 90 deg)"},
  };
  namespace fs = std::filesystem;
  for (const Case& c : cases) {
    const std::string db = ::testing::TempDir() + "/history_bad_row.sqlite";
    fs::remove(db);
    ASSERT_TRUE(MakeOldHistory(db, good_runs + c.sql)) << c.sql;
    const auto size = fs::file_size(db);
    for (int reader = 0; reader < 4; ++reader) {
      try {
        if (reader == 0) ReadHistoryRuns(db);
        if (reader == 1) ReadHistoryTrends(db);
        if (reader == 2) ReadHistorySetAside(db);
        if (reader == 3) AppendToHistory(db, {0, "2026-11-03T02:00:00Z", "/r.yaml", "/n3", "", ""}, Result(0.2, true));
        ADD_FAILURE() << "reader " << reader << " took the bad row of: " << c.sql;
      } catch (const InputError& e) {
        EXPECT_EQ(e.where(), db);
        EXPECT_EQ(e.problem().find("a bad row in the history: " + c.problem), 0u)
            << "reader " << reader << ": " << e.problem();
      }
    }
    EXPECT_EQ(fs::file_size(db), size) << c.sql;
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open_v2(db.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(raw, "SELECT count(*) FROM stereorig_check_runs;", -1, &s, nullptr);
    sqlite3_step(s);
    EXPECT_EQ(sqlite3_column_int(s, 0), 2) << "appended to: " << c.sql;
    sqlite3_finalize(s);
    sqlite3_close(raw);
  }

  // A table without a column of ours (the append would fail on it at the
  // end of the night: "no column named samples") is refused as it is read.
  const std::string db = ::testing::TempDir() + "/history_no_column.sqlite";
  fs::remove(db);
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw,
                         "CREATE TABLE stereorig_check_runs (id INTEGER PRIMARY KEY, date_utc TEXT, rig_file TEXT, "
                         "captures TEXT, verdict TEXT, explanation TEXT); CREATE TABLE stereorig_check_figures (run_id "
                         "INTEGER, name TEXT, value REAL, threshold REAL, pass INTEGER);",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(raw);
  try {
    ReadHistoryRuns(db);
    ADD_FAILURE() << "a figures table without samples was read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(),
              "the history's table stereorig_check_figures has no column samples: not a history stereorig wrote (give "
              "another with --history-db)");
  }
}

// Text that is not UTF-8 (a path's bytes, as a folder may be named) or holds
// a control byte is kept, read back escaped \xNN: printed raw it reached the
// terminal, and --json could not write it.
TEST(History, TextThatIsNotUtf8IsReadEscaped) {
  const std::string db = ::testing::TempDir() + "/history_bytes.sqlite";
  std::filesystem::remove(db);
  ASSERT_TRUE(MakeOldHistory(db,
                             "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) "
                             "VALUES ('2026-11-01T02:00:00Z', '/r.yaml', CAST(X'2F6EFF1B5B326A' AS TEXT), 'ok', "
                             "'every figure within its threshold');"));
  const auto runs = ReadHistoryRuns(db);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].captures, "/n\\xFF\\x1B[2j");
}

// A new history's tables refuse such rows themselves (CHECK constraints),
// whoever writes them.
TEST(History, NewTablesRefuseRowsNoCheckWrites) {
  const std::string db = ::testing::TempDir() + "/history_checks.sqlite";
  std::filesystem::remove(db);
  HistoryRun run{0, "2026-11-01T02:00:00Z", "/r.yaml", "/n", "", ""};
  run.rig_crc32 = "0badc0de", run.k_sigma = 3, run.captures_crc32 = "12345678";
  AppendToHistory(db, run, Result(0.2, true));
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
  for (const char* sql :
       {"UPDATE stereorig_check_figures SET value = 'abc';", "UPDATE stereorig_check_figures SET threshold = 9e999;",
        "UPDATE stereorig_check_figures SET name = '';", "UPDATE stereorig_check_figures SET pass = 7;",
        "UPDATE stereorig_check_figures SET samples = -1;", "UPDATE stereorig_check_runs SET verdict = 'banana';",
        "UPDATE stereorig_check_runs SET date_utc = X'FF00';",
        "UPDATE stereorig_check_runs SET date_utc = 'yesterday';",
        "UPDATE stereorig_check_run_inputs SET rig_crc32 = 'xyz';",
        "UPDATE stereorig_check_run_inputs SET k_sigma = -1;",
        "UPDATE stereorig_check_run_inputs SET captures_crc32 = 'ABCDEFGH';",
        "INSERT INTO stereorig_check_views_set_aside VALUES (1, '006', 5, 0.04, 0.06, 95.0);",
        "INSERT INTO stereorig_check_views_set_aside VALUES (1, '006', 5, 0.04, 0.06, 'steep');"})
    EXPECT_NE(sqlite3_exec(raw, sql, nullptr, nullptr, nullptr), SQLITE_OK) << sql;
  EXPECT_EQ(sqlite3_exec(raw, "UPDATE stereorig_check_figures SET value = 1;", nullptr, nullptr, nullptr), SQLITE_OK);
  // The positive control of the tilt rows above: a view set aside 80 deg
  // from face-on (within 0-90 deg, a number) is a row the table takes, so
  // the 95.0 and 'steep' rows were refused for their tilt alone.
  EXPECT_EQ(sqlite3_exec(raw, "INSERT INTO stereorig_check_views_set_aside VALUES (1, '006', 5, 0.04, 0.06, 80.0);",
                         nullptr, nullptr, nullptr),
            SQLITE_OK)
      << sqlite3_errmsg(raw);
  sqlite3_close(raw);
  EXPECT_EQ(ReadHistoryTrends(db)[0].points[0].value, 1.0);  // an integer in a REAL column: a number
}

// A huge number (finite: 1e308, which a corrupt row held) is printed
// bounded, not as 309 digits that broke the table.
TEST(History, HugeNumbersKeepTheTableInShape) {
  HistoryRun run{1, "2026-11-01T02:00:00Z", "/r.yaml", "/n", "ok", "every figure within its threshold"};
  const std::vector<FigureTrend> trends = {{"cam0_x", {{1, run.date_utc, 1e-300, 1e308, true}}}};
  const std::string table = FormatTrends({run}, trends) + FormatRunSeries({run}, trends, 31);
  EXPECT_NE(table.find("cam0_x                                       1     0.0000     0.0000     0.0000     0.0000 "
                       "    1e+308      0\n"),
            std::string::npos)
      << table;
  size_t longest = 0;
  std::istringstream lines(table);
  for (std::string line; std::getline(lines, line);) longest = std::max(longest, line.size());
  EXPECT_LT(longest, 120u) << table;
}

}  // namespace
}  // namespace stereorig
