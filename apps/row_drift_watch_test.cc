// RowDriftWatch on made-up readings whose mean and standard error are known.
#include "apps/row_drift_watch.h"

#include <gtest/gtest.h>

#include <cmath>
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
// errors) in turn, and once -0.09 (3.6 standard errors, a capture's noise).
// Its mean over the last 20 stays near -0.02: never warned.
TEST(RowDriftWatch, NoiseAboutACalibrationOffsetIsNeverWarned) {
  RowDriftWatch watch(0.1);
  for (int i = 0; i < 60; ++i) {
    const double noise = i == 30 ? -0.07 : (i % 2 ? 0.05 : -0.05);
    const std::vector<RowDrift> means = watch.Add(Capture(-0.02 + noise, 0.0));
    ASSERT_EQ(means.size(), 2u);
    EXPECT_FALSE(means[0].warned) << i;
    EXPECT_TRUE(means[0].read);
    EXPECT_EQ(means[0].captures, std::min(i + 1, RowDriftWatch::kCaptures));
  }
}

// A module turned 0.15 px at capture 20 (its readings then 0.15, each with
// a standard error of 0.025): the mean of the last 20 passes 0.1 px once 14
// of them are turned (14 x 0.15 / 20 = 0.105; its standard error 0.025 /
// sqrt(20) = 0.0056); the other module is never warned. Turned back, the
// warning ends when fewer than 14 of the last 20 are turned.
TEST(RowDriftWatch, APersistentDriftIsWarnedOnceTheMeanOfTheLastCapturesPassesTheTolerance) {
  RowDriftWatch watch(0.1);
  for (int i = 0; i < 20; ++i) watch.Add(Capture(0.0, 0.0));
  for (int k = 1; k <= 20; ++k) {
    const std::vector<RowDrift> means = watch.Add(Capture(0.15, 0.0));
    EXPECT_EQ(means[0].warned, k >= 14) << k;
    EXPECT_NEAR(means[0].row_offset_px, k * 0.15 / 20, 1e-12);
    EXPECT_NEAR(means[0].standard_error_px, 0.025 / std::sqrt(20.0), 1e-12);
    EXPECT_FALSE(means[1].warned);
  }
  for (int k = 1; k <= 10; ++k) EXPECT_EQ(watch.Add(Capture(0.0, 0.0))[0].warned, k <= 6) << k;
}

// One capture alone is judged as RowDriftWarned judges it: 0.12 px is past
// 0.1 and 4 x 0.025; with a standard error of 0.04, 4 of them are 0.16.
TEST(RowDriftWatch, TheFirstCaptureIsJudgedAlone) {
  EXPECT_TRUE(RowDriftWatch(0.1).Add(Capture(0.12, 0.0))[0].warned);
  EXPECT_FALSE(RowDriftWatch(0.1).Add(Capture(0.12, 0.0, 0.04))[0].warned);
}

// A module the line index does not run on (passive options) reads nothing:
// it adds no reading and is not read.
TEST(RowDriftWatch, AModuleNotReadAddsNothing) {
  RowDriftWatch watch(0.1);
  std::vector<ModuleReport> modules = Capture(0.3, 0.3);
  modules[1].row_drift = RowDrift{};
  const std::vector<RowDrift> means = watch.Add(modules);
  EXPECT_TRUE(means[0].warned);
  EXPECT_FALSE(means[1].read);
  EXPECT_FALSE(means[1].warned);
  EXPECT_EQ(means[1].captures, 0);
}

}  // namespace
}  // namespace stereorig
