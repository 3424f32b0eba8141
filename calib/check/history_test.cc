#include "calib/check/history.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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
    r.camera_changes = {moved};
  }
  return r;
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
  EXPECT_EQ(runs[2].explanation, "camera 0 moved");
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

}  // namespace
}  // namespace stereorig
