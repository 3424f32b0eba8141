#include "apps/module_summary.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

ModuleReport Report() {
  ModuleReport m;
  m.module = 1;
  m.points = 600;
  m.lit_pixels = 1000;
  m.lit_filled = 600;
  m.min_disparity_px = -100;
  m.num_disparities = 274;
  m.searched_min_disparity_px = 35;
  m.searched_num_disparities = 85;
  m.times_ms["match"] = 82.75;
  return m;
}

TEST(ModuleSummary, NamesTheBandAndTheLargestLossesLargestFirst) {
  ModuleReport m = Report();
  m.lit_by_status[size_t(PixelStatus::kPoint)] = 600;
  m.lit_by_status[size_t(PixelStatus::kLowZncc)] = 50;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 200;
  m.lit_by_status[size_t(PixelStatus::kWrongLine)] = 125;
  m.lit_by_status[size_t(PixelStatus::kSpeckle)] = 25;
  EXPECT_EQ(ModuleSummary(m),
            "module 1: 600 points, fill 60.0% of 1000 grid-lit px, match 82.8 ms\n"
            "  searched d [35, 120) of [-100, 174) px; lit px without a point: no_sgm_match 20.0%, wrong_line 12.5%, "
            "low_zncc 5.0%, ...");
  EXPECT_EQ(ModuleSummary(m, 4).substr(ModuleSummary(m, 4).rfind(',') + 1), " speckle 2.5%");
}

TEST(ModuleSummary, SaysNoneWhenEveryLitPixelHasAPoint) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 1000;
  m.lit_by_status[size_t(PixelStatus::kPoint)] = 1000;
  const std::string s = ModuleSummary(m);
  EXPECT_EQ(s.substr(s.find('\n') + 1), "  searched d [35, 120) of [-100, 174) px; lit px without a point: none");
}

// A module whose lit pixels all went without a point (the walkthrough's
// 300 mm rig under the default 200 mm volume: no_sgm_match 85.6 %) says
// where to look; one with a point, or with nothing lit, does not.
TEST(ModuleSummary, NoPointAtAllNamesTheMeasurementVolume) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 0;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 1000;
  const std::string s = ModuleSummary(m);
  EXPECT_NE(s.find("\n  no point: if the object is not in the measurement volume, set working_distance_mm"),
            std::string::npos)
      << s;
  m.points = 1;
  EXPECT_EQ(ModuleSummary(m).find("no point:"), std::string::npos);
  m.points = 0;
  m.lit_pixels = 0;
  EXPECT_EQ(ModuleSummary(m).find("no point:"), std::string::npos);
}

}  // namespace
}  // namespace stereorig
