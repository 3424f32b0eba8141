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
  EXPECT_EQ(ModuleSummary(m, {}, 4).substr(ModuleSummary(m, {}, 4).rfind(',') + 1), " speckle 2.5%");
}

TEST(ModuleSummary, SaysNoneWhenEveryLitPixelHasAPoint) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 1000;
  m.lit_by_status[size_t(PixelStatus::kPoint)] = 1000;
  const std::string s = ModuleSummary(m);
  EXPECT_EQ(s.substr(s.find('\n') + 1), "  searched d [35, 120) of [-100, 174) px; lit px without a point: none");
}

// A module whose lit pixels all went without a point says where to look,
// after the status most of them ended with: the walkthrough's 300 mm rig
// under the default 200 mm volume (no_sgm_match 85.6 %) names the volume;
// a module whose points object_size took (78 %) names object_size_mm, not
// the volume, which was right; a passive capture (not_distinct) the
// passive options. Before, every one was told to move the volume. One with
// a point gets no hint.
TEST(ModuleSummary, NoPointAtAllFollowsTheLitPixelsTopStatus) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 0;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 856;
  m.lit_by_status[size_t(PixelStatus::kNoPlane)] = 144;
  std::string s = ModuleSummary(m);
  EXPECT_NE(s.find("\n  no point: no_sgm_match 85.6% of the lit pixels: the search found no consistent match: the "
                   "object may not be in the measurement volume (set working_distance_mm"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("its cameras swapped or moved"), std::string::npos) << s;
  m.lit_by_status = {};
  m.lit_by_status[size_t(PixelStatus::kObjectSize)] = 780;
  m.lit_by_status[size_t(PixelStatus::kLowZncc)] = 220;
  s = ModuleSummary(m);
  EXPECT_NE(s.find("\n  no point: object_size 78.0% of the lit pixels: they lie farther than object_size_mm from the "
                   "module's median point: set object_size_mm"),
            std::string::npos)
      << s;
  EXPECT_EQ(s.find("working_distance_mm"), std::string::npos) << s;
  m.lit_by_status = {};
  m.lit_by_status[size_t(PixelStatus::kNotDistinct)] = 600;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 400;
  s = ModuleSummary(m);
  EXPECT_NE(s.find("no point: not_distinct 60.0% of the lit pixels: the laser grid's own tests refused their "
                   "matches: a capture without the laser grid (passive) needs crop_to_lit_region: false"),
            std::string::npos)
      << s;
  m.points = 1;
  EXPECT_EQ(ModuleSummary(m).find("no point:"), std::string::npos);
}

// A passive run (the demo's passive_options.yaml) of a plain plate matches
// nothing: the advice told the user to set the passive options they had
// set. With passive options it says what a passive capture of weak texture
// gives instead, and still names the volume and a swapped pair.
TEST(ModuleSummary, NoPointUnderPassiveOptionsDoesNotAskForThem) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 0;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 698;
  m.lit_by_status[size_t(PixelStatus::kNoPlane)] = 302;
  const std::string passive = NoPointReason(m, true);
  EXPECT_EQ(passive.find("crop_to_lit_region"), std::string::npos) << passive;
  EXPECT_NE(passive.find("no_sgm_match 69.8% of the lit pixels: the search found no consistent match: without the "
                         "laser grid (these options are passive) a weakly textured surface"),
            std::string::npos)
      << passive;
  EXPECT_NE(passive.find("set working_distance_mm"), std::string::npos) << passive;
  EXPECT_NE(passive.find("its cameras swapped or moved"), std::string::npos) << passive;
  EXPECT_EQ(ModuleSummary(m, {.passive = true}).find("crop_to_lit_region"), std::string::npos);
  // Active options: the passive ones are still the hint (a passive capture
  // run with the active options).
  EXPECT_NE(NoPointReason(m, false).find("needs crop_to_lit_region: false"), std::string::npos);
  EXPECT_NE(ModuleSummary(m).find("needs crop_to_lit_region: false"), std::string::npos);
}

// No lit pixel where the volume projects: the hint used to need lit pixels,
// so a volume beside the object gave an empty module and no word. Now the
// left camera's whole image tells a volume beside the object (lit
// elsewhere: where to set the volume) from a dark or flat capture.
TEST(ModuleSummary, NoLitPixelInTheVolumeSaysWhetherTheImageIsLitElsewhere) {
  ModuleReport m = Report();
  m.points = m.lit_filled = m.lit_pixels = 0;
  m.camera_lit_pixels = 164311;
  EXPECT_NE(ModuleSummary(m).find("\n  no point: 164311 px of the left camera's image are grid-lit, none where the "
                                  "measurement volume projects: the volume is beside the object; set "
                                  "working_distance_mm (or volume_center_mm, volume_size_mm) to where it is"),
            std::string::npos)
      << ModuleSummary(m);
  m.camera_lit_pixels = 0;
  EXPECT_NE(ModuleSummary(m).find("\n  no point: no lit pixels: is the projector on, or is this a passive capture? "
                                  "No pixel of the left camera's image is grid-lit (9x9 std above lit_contrast_dn): "
                                  "a dark or flat image"),
            std::string::npos)
      << ModuleSummary(m);
  EXPECT_EQ(ModuleSummary(m).find("working_distance_mm"), std::string::npos) << ModuleSummary(m);
  m.camera_lit_pixels = -1;  // not counted: both causes stay open
  EXPECT_NE(ModuleSummary(m).find("\n  no point: no grid-lit pixel where the measurement volume projects: if the "
                                  "object is not in the volume, set working_distance_mm"),
            std::string::npos)
      << ModuleSummary(m);
}

// The band pass's kept bins within one bin (4 px) of an end of the
// volume's range are warned of, naming the end; farther in, with no point,
// or with no band, not.
TEST(ModuleSummary, MatchesReachingAnEndOfTheRangeAreWarnedOf) {
  ModuleReport m = Report();  // range [-100, 174)
  auto ends = [&] {
    const ModuleReport::RangeEnds e = m.RangeEndsReached();
    return std::string(e.far ? "far" : "") + (e.near ? "near" : "");
  };
  m.occupied_min_disparity_px = 35;
  m.occupied_end_disparity_px = 120;
  EXPECT_EQ(ends(), "");
  EXPECT_EQ(ModuleSummary(m).find("warning:"), std::string::npos);
  m.occupied_end_disparity_px = 170;  // 4 px from the range's end, 174
  EXPECT_EQ(ends(), "near");
  EXPECT_NE(ModuleSummary(m).find("\n  warning: its matches reach the near end of the measurement volume's disparity "
                                  "range (the band pass's d [35, 170) of [-100, 174) px)"),
            std::string::npos)
      << ModuleSummary(m);
  m.occupied_end_disparity_px = 169;
  EXPECT_EQ(ends(), "");
  m.occupied_min_disparity_px = -96;  // 4 px from -100
  EXPECT_EQ(ends(), "far");
  EXPECT_NE(ModuleSummary(m).find("reach the far end of the measurement volume's disparity range"), std::string::npos)
      << ModuleSummary(m);
  m.occupied_min_disparity_px = -95;
  EXPECT_EQ(ends(), "");
  m.occupied_min_disparity_px = -100;
  m.occupied_end_disparity_px = 174;
  EXPECT_EQ(ends(), "farnear");
  EXPECT_NE(ModuleSummary(m).find("reach both ends of"), std::string::npos) << ModuleSummary(m);
  m.points = 0;
  EXPECT_EQ(ModuleSummary(m).find("warning:"), std::string::npos);
  m.points = 600;
  m.occupied_end_disparity_px = m.occupied_min_disparity_px;  // no band found
  EXPECT_EQ(ends(), "");
}

// A right camera not triggered (its image dark) while the left is lit: the
// left's pixels end as no_sgm_match, which was put down to the volume. The
// dark right image is named first, with no word of the volume; lit, or
// not counted (-1), the advice is as before.
TEST(ModuleSummary, ADarkRightImageIsNamedNotTheVolume) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 0;
  m.left_camera = 2;
  m.right_camera = 3;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 1000;
  m.right_camera_lit_pixels = 0;
  const std::string dark = ModuleSummary(m);
  EXPECT_NE(dark.find("\n  no point: no pixel of the right camera's image (cam3.png) is grid-lit (9x9 std above "
                      "lit_contrast_dn), while the left camera's (cam2.png) is: a dark or flat right image (that "
                      "camera not triggered"),
            std::string::npos)
      << dark;
  EXPECT_EQ(dark.find("working_distance_mm"), std::string::npos) << dark;
  m.lit_pixels = 0;  // the left lit only beside the volume: still the right camera
  m.camera_lit_pixels = 5000;
  EXPECT_NE(ModuleSummary(m).find("no point: no pixel of the right camera's image (cam3.png)"), std::string::npos)
      << ModuleSummary(m);
  m.camera_lit_pixels = 0;  // both dark: the projector, as before
  EXPECT_NE(ModuleSummary(m).find("no point: no lit pixels: is the projector on"), std::string::npos)
      << ModuleSummary(m);
  m.lit_pixels = 1000;
  m.camera_lit_pixels = -1;
  for (const int right_lit : {-1, 4000}) {
    m.right_camera_lit_pixels = right_lit;
    EXPECT_NE(ModuleSummary(m).find("no point: no_sgm_match 100.0% of the lit pixels: the search found no consistent "
                                    "match: the object may not be in the measurement volume"),
              std::string::npos)
        << ModuleSummary(m);
  }
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// A module whose lit pixels mostly ended wrong_line (the line index could
// not tell the lines apart: 0.2 px of rows off left the demo cup's module 0
// at 1 % fill, 78 % wrong_line) is told the rig's rows may be off and to run
// the check, besides the grid's own options.
TEST(ModuleSummary, NoPointMostlyWrongLineNamesTheRowsAndTheCheck) {
  ModuleReport m = Report();
  m.points = m.lit_filled = 0;
  m.lit_by_status[size_t(PixelStatus::kWrongLine)] = 780;
  m.lit_by_status[size_t(PixelStatus::kNoSgmMatch)] = 220;
  const std::string s = ModuleSummary(m);
  EXPECT_NE(s.find("\n  no point: wrong_line 78.0% of the lit pixels: the line index could not tell which laser line "
                   "they are on: the rig's rows may be off (a camera turned since calibration: run `stereorig check`)"),
            std::string::npos)
      << s;
}

}  // namespace
}  // namespace stereorig
