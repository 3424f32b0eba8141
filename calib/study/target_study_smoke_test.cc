// Smoke test of the target study program: a tiny configuration (one board,
// one small capture count, 2 seeds, 1 thread) runs, and its CSV is sane.
// At the study's 0.031 px corner noise even 12 captures calibrate the
// default rig far inside the 0.05 mm bounds (the full study measures
// p95 figures of a few micrometres), so the bounds below are loose on
// purpose: they catch a broken pipeline, not a small regression.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

TEST(TargetStudy, TinyConfigurationGivesSaneFigures) {
  const std::string csv = ::testing::TempDir() + "/target_study_smoke.csv";
  const std::string cmd = std::string(TARGET_STUDY_BIN) +
                          " --boards 9x7@10 --captures 12 --seeds 2 --threads 1 --csv " + csv + " > " + csv +
                          ".out 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream f(csv);
  std::string header, row;
  ASSERT_TRUE(std::getline(f, header));
  EXPECT_EQ(header.rfind("board,captures,", 0), 0u) << header;
  ASSERT_TRUE(std::getline(f, row));
  std::vector<std::string> cells;
  std::stringstream in(row);
  for (std::string c; std::getline(in, c, ',');) cells.push_back(c);
  ASSERT_EQ(cells.size(), 8u) << row;
  EXPECT_EQ(cells[0], "9x7@10");
  EXPECT_EQ(cells[1], "12");
  const double corners_per_view = std::stod(cells[2]);
  EXPECT_GE(corners_per_view, 8.0);   // a view needs 8 corners to count
  EXPECT_LE(corners_per_view, 63.0);  // 9 x 7 corners at most
  for (int k : {3, 4, 5}) {
    const double v = std::stod(cells[k]);
    EXPECT_TRUE(std::isfinite(v)) << row;
    EXPECT_GT(v, 0.0) << row;
    EXPECT_LT(v, 0.05) << "column " << k << ": " << row;
  }
  EXPECT_EQ(cells[7], "0") << "failed calibrations: " << row;
  EXPECT_FALSE(std::getline(f, row)) << "one board x one count = one row";
}

}  // namespace
