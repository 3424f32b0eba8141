// RowDriftWatch on made-up readings whose mean and standard error are known.
#include "apps/row_drift_watch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace stereorig {
namespace {

std::vector<ModuleReport> Capture(double module0_px, double module1_px, double se_px = 0.025) {
  std::vector<ModuleReport> modules(2);
  for (int k = 0; k < 2; ++k) {
    modules[size_t(k)].module = k;
    RowDrift& d = modules[size_t(k)].row_drift;
    d.read = true, d.captures = 1, d.components = 1, d.pixels = 1000;
    d.row_offset_px = k == 0 ? module0_px : module1_px;
    d.standard_error_px = se_px;
  }
  return modules;
}

// A calibrated module's readings scatter with their standard error about a
// small offset of its calibration's: here -0.02 px, +-0.05 px (2 standard
// errors) in turn, and once -0.09 (2.8 standard errors about -0.02, a
// capture's noise). The mean size of the last 20 stays near 0.05: never
// warned.
TEST(RowDriftWatch, NoiseAboutACalibrationOffsetIsNeverWarned) {
  RowDriftWatch watch(0.1);
  std::vector<double> sizes;
  for (int i = 0; i < 60; ++i) {
    const double reading = -0.02 + (i == 30 ? -0.07 : (i % 2 ? 0.05 : -0.05));
    sizes.push_back(std::abs(reading));
    const std::vector<WatchedRowDrift> states = watch.Add(Capture(reading, 0.0));
    ASSERT_EQ(states.size(), 2u);
    EXPECT_FALSE(states[0].warned) << i;
    EXPECT_TRUE(states[0].recent.read);
    // The mean size of the last 20 (or fewer, at the start): 0.03 and 0.07 in turn, once 0.09.
    const size_t n = std::min<size_t>(sizes.size(), RowDriftWatch::kCaptures);
    double sum = 0;
    for (size_t k = sizes.size() - n; k < sizes.size(); ++k) sum += sizes[k];
    EXPECT_EQ(states[0].recent.captures, int(n));
    EXPECT_NEAR(states[0].recent.row_offset_px, sum / double(n), 1e-12) << i;
  }
}

// A module turned 0.15 px at capture 21 (its readings then 0.15, each with
// a standard error of 0.025): the mean size of the last 20 passes 0.1 px
// once 14 of them are turned (14 x 0.15 / 20 = 0.105; its standard error
// 0.025 / sqrt(20) = 0.0056), at capture 34; the other module is never
// warned. Turned back, the warning stays: a module past ~0.2 px reads small.
TEST(RowDriftWatch, APersistentDriftIsWarnedOnceTheMeanOfTheLastCapturesPassesTheToleranceAndStays) {
  RowDriftWatch watch(0.1);
  for (int i = 0; i < 20; ++i) watch.Add(Capture(0.0, 0.0));
  for (int k = 1; k <= 20; ++k) {
    const std::vector<WatchedRowDrift> states = watch.Add(Capture(0.15, 0.0));
    EXPECT_EQ(states[0].warned, k >= 14) << k;
    EXPECT_EQ(states[0].warned_since, k >= 14 ? 34 : 0) << k;
    EXPECT_NEAR(states[0].recent.row_offset_px, k * 0.15 / 20, 1e-12);
    EXPECT_NEAR(states[0].recent.standard_error_px, 0.025 / std::sqrt(20.0), 1e-12);
    EXPECT_FALSE(states[1].warned);
  }
  for (int k = 1; k <= 30; ++k) {
    const WatchedRowDrift state = watch.Add(Capture(0.0, 0.0))[0];
    EXPECT_TRUE(state.warned) << k;
    EXPECT_EQ(state.warned_since, 34);
    EXPECT_EQ(RowDriftWarned(state.recent, 0.1), k <= 6) << k;  // the mean itself falls back
  }
}

// Past half the vernier's step the readings wrap and change sign from
// capture to capture (a second reading's, 0.25 px of rows on the demo's
// five scenes): signed they average -0.054, under the tolerance; their
// sizes average 0.139 and are warned of from the first.
TEST(RowDriftWatch, ReadingsThatWrapAreJudgedByTheirSizes) {
  RowDriftWatch watch(0.1);
  const double readings[] = {-0.111, -0.098, +0.261, -0.081, -0.142};
  double sum_size = 0;
  for (int k = 0; k < 5; ++k) {
    sum_size += std::abs(readings[k]);
    const WatchedRowDrift state = watch.Add(Capture(readings[k], 0.0))[0];
    EXPECT_TRUE(state.warned) << k;
    EXPECT_EQ(state.warned_since, 1);
    EXPECT_NEAR(state.recent.row_offset_px, sum_size / (k + 1), 1e-12);
  }
}

// One capture alone is judged as RowDriftWarned judges it: 0.12 px is past
// 0.1 and 4 x 0.025; with a standard error of 0.04, 4 of them are 0.16.
TEST(RowDriftWatch, TheFirstCaptureIsJudgedAlone) {
  EXPECT_TRUE(RowDriftWatch(0.1).Add(Capture(-0.12, 0.0))[0].warned);
  EXPECT_FALSE(RowDriftWatch(0.1).Add(Capture(0.12, 0.0, 0.04))[0].warned);
}

// A module the line index does not run on (passive options) reads nothing:
// it adds no reading and is not read.
TEST(RowDriftWatch, AModuleNotReadAddsNothing) {
  RowDriftWatch watch(0.1);
  std::vector<ModuleReport> modules = Capture(0.3, 0.3);
  modules[1].row_drift = RowDrift{};
  const std::vector<WatchedRowDrift> states = watch.Add(modules);
  EXPECT_TRUE(states[0].warned);
  EXPECT_FALSE(states[1].recent.read);
  EXPECT_FALSE(states[1].warned);
  EXPECT_EQ(states[1].recent.captures, 0);
}

// A module whose matches reach `ends` of its disparity range [0, 200) px:
// its band's kept bins [0, 200) for both, [100, 200) near, [0, 100) far.
ModuleReport Reading(int module, double row_offset_px, double se_px, const char* ends = "none") {
  ModuleReport m;
  m.module = module;
  m.min_disparity_px = 0, m.num_disparities = 200;
  const std::string e = ends;
  m.occupied_min_disparity_px = e == "both" || e == "far" ? 0 : 100;
  m.occupied_end_disparity_px = e == "both" || e == "near" ? 200 : e == "far" ? 100 : 150;
  RowDrift& d = m.row_drift;
  d.read = true, d.captures = 1, d.components = 5, d.pixels = 10000;
  d.row_offset_px = row_offset_px;
  d.standard_error_px = se_px;
  return m;
}

// Module 0's readings in a stream of the tuber then the line's other
// objects, the volume at 210 mm (measured, reports of `reconstruct
// --capture -`): the tuber partly outside the volume, 1.4 % fill, its
// matches reaching both ends of the range, read -0.409 px (standard error
// 0.016): the grid matched a period off reads a whole step (0.36 px) off.
// The captures after it read 0.001, -0.002 (its matches reaching the near
// end) and -0.067 px in turn.
struct Measured {
  double row_offset_px, se_px;
  const char* ends;
};
constexpr Measured kTuberOutsideTheVolume = {-0.409, 0.016, "both"};
constexpr Measured kLineAfterIt[] = {{0.0013, 0.019, "none"}, {-0.0017, 0.024, "near"}, {-0.0666, 0.022, "none"}};

// Not counted: the reading from a module reaching an end of its range says
// nothing of its rows. Before, that one reading warned (the mean of one)
// and the warning stayed for all 19 captures.
TEST(RowDriftWatch, AReadingFromAModuleReachingAnEndOfItsRangeIsNotCounted) {
  RowDriftWatch watch(0.1);
  WatchedRowDrift state =
      watch.Add({Reading(0, kTuberOutsideTheVolume.row_offset_px, kTuberOutsideTheVolume.se_px, "both")})[0];
  EXPECT_EQ(state.not_counted, "range_end_reached");
  EXPECT_FALSE(state.recent.read);
  EXPECT_FALSE(state.warned);
  for (int k = 0; k < 18; ++k) {
    const Measured& r = kLineAfterIt[k % 3];
    state = watch.Add({Reading(0, r.row_offset_px, r.se_px, r.ends)})[0];
    EXPECT_FALSE(state.warned) << k;
    EXPECT_EQ(state.not_counted, std::string(r.ends) == "none" ? "" : "range_end_reached") << k;
  }
  EXPECT_EQ(state.recent.captures, 12);  // the near end's six not counted
}

// The same readings with the first one's range end not seen (a reading a
// step off that no flag catches): warned while the mean of the few
// readings there are passes 0.1 px and 4 standard errors, withdrawn at the
// first capture where it does not, and not warned after: on fewer than 20
// readings a warning is not for the run.
TEST(RowDriftWatch, AWarningOnFewerReadingsThanAWindowIsWithdrawnWhenTheirMeanFallsBack) {
  RowDriftWatch watch(0.1);
  std::vector<double> sizes = {std::abs(kTuberOutsideTheVolume.row_offset_px)};
  std::vector<double> variances = {kTuberOutsideTheVolume.se_px * kTuberOutsideTheVolume.se_px};
  WatchedRowDrift state =
      watch.Add({Reading(0, kTuberOutsideTheVolume.row_offset_px, kTuberOutsideTheVolume.se_px)})[0];
  EXPECT_TRUE(state.warned);
  EXPECT_TRUE(state.started);
  EXPECT_FALSE(state.stays);
  int withdrawn_at = 0;
  for (int k = 0; k < 18; ++k) {
    const Measured& r = kLineAfterIt[k % 3];
    state = watch.Add({Reading(0, r.row_offset_px, r.se_px, r.ends)})[0];
    if (std::string(r.ends) == "none") {
      sizes.push_back(std::abs(r.row_offset_px));
      variances.push_back(r.se_px * r.se_px);
    }
    double sum = 0, var = 0;
    for (size_t i = 0; i < sizes.size(); ++i) sum += sizes[i], var += variances[i];
    const double mean = sum / double(sizes.size()), se = std::sqrt(var) / double(sizes.size());
    const bool expect = withdrawn_at == 0 && mean > 0.1 && mean > 4 * se;
    EXPECT_EQ(state.warned, expect) << k;
    EXPECT_FALSE(state.stays) << k;
    if (state.withdrawn_since != 0) {
      EXPECT_EQ(withdrawn_at, 0) << k;
      EXPECT_EQ(state.withdrawn_since, 1);
      withdrawn_at = k + 2;
    }
  }
  EXPECT_GT(withdrawn_at, 2);  // warned over a few captures first: 0.409 and 0.001 average 0.205
  EXPECT_FALSE(state.warned);
}

// The docs' camera turned 0.15 px, reading +0.138 (standard error 0.025)
// at every capture from the run's first, after the tuber outside the
// volume: warned from the first counted reading (capture 2), for the run
// once the mean of a full window of 20 warns (capture 21), and then it
// stays with its readings coming back small (past ~0.2 px a module reads
// small again).
TEST(RowDriftWatch, ATurnedCameraIsWarnedFromItsFirstReadingAndForTheRunOnceAWindowIsFull) {
  RowDriftWatch watch(0.1);
  EXPECT_FALSE(watch.Add({Reading(0, kTuberOutsideTheVolume.row_offset_px, 0.016, "both")})[0].warned);
  for (int capture = 2; capture <= 40; ++capture) {
    const WatchedRowDrift state = watch.Add({Reading(0, 0.138, 0.025)})[0];
    EXPECT_TRUE(state.warned) << capture;
    EXPECT_EQ(state.started, capture == 2) << capture;
    EXPECT_EQ(state.warned_since, 2) << capture;
    EXPECT_EQ(state.stays, capture >= 21) << capture;
  }
  for (int k = 0; k < 30; ++k) {
    const WatchedRowDrift state = watch.Add({Reading(0, 0.02, 0.025)})[0];
    EXPECT_TRUE(state.warned) << k;
    EXPECT_EQ(state.withdrawn_since, 0) << k;
  }
}

// The tuber outside the volume for the whole run (its readings measured
// above, each reaching both ends): none counted, so the module's drift is
// never judged. Told once, at the 20th such reading (a full window's
// captures), not before nor after; module 1, counted at each capture, never.
TEST(RowDriftWatch, AModuleWhoseReadingsAllReachARangeEndIsToldUnjudgedOnceAtAFullWindow) {
  RowDriftWatch watch(0.1);
  for (int capture = 1; capture <= 45; ++capture) {
    const std::vector<WatchedRowDrift> states =
        watch.Add({Reading(0, kTuberOutsideTheVolume.row_offset_px, kTuberOutsideTheVolume.se_px, "both"),
                   Reading(1, 0.01, 0.02)});
    EXPECT_EQ(states[0].unjudged, capture == RowDriftWatch::kCaptures) << capture;
    EXPECT_EQ(states[0].not_counted_in_a_row, capture) << capture;
    EXPECT_EQ(states[0].counted_before, 0);
    EXPECT_FALSE(states[0].warned) << capture;
    EXPECT_FALSE(states[1].unjudged) << capture;
    EXPECT_EQ(states[1].not_counted_in_a_row, 0);
    // Before the 20th, the run's end would tell it (a run that short).
    const std::vector<UnjudgedRowDrift> unjudged = watch.Unjudged();
    ASSERT_EQ(unjudged.size(), 1u) << capture;
    EXPECT_EQ(unjudged[0].module, 0);
    EXPECT_EQ(unjudged[0].unjudged_since, capture >= RowDriftWatch::kCaptures ? RowDriftWatch::kCaptures : 0);
    EXPECT_EQ(unjudged[0].counted, 0);
    EXPECT_EQ(unjudged[0].not_counted, capture);
  }
}

// The measured line after the tuber: one capture in three reaching the
// near end, not counted. Its streaks of uncounted readings are one long:
// never told, over 60 captures, and not at the run's end either.
TEST(RowDriftWatch, AModuleReachingARangeEndNowAndThenIsNotToldUnjudged) {
  RowDriftWatch watch(0.1);
  for (int k = 0; k < 60; ++k) {
    const Measured& r = kLineAfterIt[k % 3];
    const WatchedRowDrift state = watch.Add({Reading(0, r.row_offset_px, r.se_px, r.ends)})[0];
    EXPECT_FALSE(state.unjudged) << k;
    EXPECT_LE(state.not_counted_in_a_row, 1) << k;
  }
  EXPECT_TRUE(watch.Unjudged().empty());
}

// A module counted at the run's first 5 captures, then its matches reaching
// an end at every capture (the part moved, or it stopped reading): told at
// the 20th uncounted reading in a row, 5 counted before them; a capture
// where it read nothing (no component kept) neither breaks the run of
// uncounted readings nor adds to it. Counted again, the count starts anew,
// and it is not told a second time in the run.
TEST(RowDriftWatch, ACountedModuleThatStopsBeingCountedIsToldUnjudgedOnce) {
  RowDriftWatch watch(0.1);
  for (int k = 0; k < 5; ++k) watch.Add({Reading(0, 0.02, 0.02)});
  int told_at = 0, capture = 5;
  for (int k = 1; k <= 20; ++k) {
    ++capture;
    if (k == 10) {
      ModuleReport unread = Reading(0, 0.0, 0.0, "far");
      unread.row_drift = RowDrift{};
      const WatchedRowDrift state = watch.Add({unread})[0];
      EXPECT_FALSE(state.unjudged);
      EXPECT_EQ(state.not_counted_in_a_row, 9);
      ++capture;
    }
    const WatchedRowDrift state = watch.Add({Reading(0, 0.3, 0.02, "far")})[0];
    EXPECT_EQ(state.not_counted_in_a_row, k);
    EXPECT_EQ(state.counted_before, 5);
    if (state.unjudged) told_at = capture;
  }
  EXPECT_EQ(told_at, 26);  // 5 counted, 20 not, one not read
  ASSERT_EQ(watch.Unjudged().size(), 1u);
  EXPECT_EQ(watch.Unjudged()[0].unjudged_since, 26);
  EXPECT_EQ(watch.Unjudged()[0].counted, 5);
  EXPECT_EQ(watch.Unjudged()[0].not_counted, 20);
  EXPECT_EQ(watch.Add({Reading(0, 0.02, 0.02)})[0].not_counted_in_a_row, 0);
  for (int k = 0; k < 30; ++k) EXPECT_FALSE(watch.Add({Reading(0, 0.3, 0.02, "near")})[0].unjudged) << k;
  EXPECT_EQ(watch.Unjudged()[0].unjudged_since, 26);  // still listed: the run had the gap
}

// A module that read nothing in the run (passive options: no line index)
// is not unjudged for a range end: it is not listed.
TEST(RowDriftWatch, AModuleThatReadNothingIsNotListedUnjudged) {
  RowDriftWatch watch(0.1);
  std::vector<ModuleReport> modules = Capture(0.0, 0.0);
  modules[0].row_drift = RowDrift{};
  modules[1].row_drift = RowDrift{};
  for (int k = 0; k < 30; ++k) EXPECT_FALSE(watch.Add(modules)[0].unjudged);
  EXPECT_TRUE(watch.Unjudged().empty());
}

}  // namespace
}  // namespace stereorig
