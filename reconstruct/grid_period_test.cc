// The grid period measured from rectified left images whose true period is
// known analytically (synthetic_pair.h renders two families of Gaussian
// lines turned by grid_angle_deg, a period p apart across the lines: along
// a row the near-vertical family is p / cos(angle) apart), and the keys
// set from it.
//
// Tolerance of the period: 0.1 % of it. The peaks' positions come from
// three-point fits, exact for Gaussian peaks; the differenced lines'
// correlation is not quite Gaussian, which leaves up to 0.064 % (5.5 px at
// 10 degrees, 0.0036 px; 31 px at 2.6 degrees, 0.0057 px) on the
// noise-free images of these periods at 2.6 and 10 degrees (1 and 5 stay
// within the tolerance too), and the 2 DN sensor noise and 15 % albedo texture the tests add move it by < 0.0006 px
// (the same images rendered without them). The keys need P to the nearest pixel.
#include "reconstruct/grid_period.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/grid_period_options.h"
#include "reconstruct/lit_mask.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

constexpr double kRelativeTolerance = 0.001;

double AlongRowPeriodPx(const SyntheticPairSpec& s) {
  return s.grid_period_px / std::cos(s.grid_angle_deg * M_PI / 180);
}

SyntheticPairSpec Grid(double period_px, double angle_deg) {
  SyntheticPairSpec s;
  s.width = 400, s.height = 160;
  s.grid_period_px = period_px;
  s.grid_angle_deg = angle_deg;  // the renderer divides by sin(angle): not 0
  return s;
}

cv::Mat AllLit(const cv::Mat& image) { return cv::Mat(image.size(), CV_8UC1, cv::Scalar(255)); }

// The period, and the grid's turn against the rows against the angle the
// renderer turns its lines by (both read from the same images). Turn
// tolerance 0.1 deg: the three-point peak positions are biased by where
// each peak falls between two lags; read at eight row separations and
// fitted, what is left on these images is <= 0.08 deg (1 deg at 5.5 px,
// where all eight peaks fall within 0.6 px of lag 0), and the row offset
// per period the vernier's thresholds need (0.2-0.9 px) is then known to
// ~4 % at the default 2.6 deg. A short period turned steeply (5.5 px at 10
// deg: the lines move 1.4 px in 8 rows) is read from the 4-row separation
// alone (8 rows would put its peak past half a period less a pixel) and
// its turn is not tested.
TEST(GridPeriod, MeasuresTheAnalyticPeriodAndTurn) {
  for (double angle : {1.0, 2.6, 5.0, 10.0})
    for (double period : {5.5, 8.0, 12.15, 31.0}) {
      const SyntheticPairSpec spec = Grid(period, angle);
      const SyntheticPair pair = RenderSyntheticPair(spec);
      const auto m = MeasureGridPeriodPx(pair.left, AllLit(pair.left));
      ASSERT_TRUE(m) << period << " px at " << angle << " deg";
      const double p = AlongRowPeriodPx(spec);
      EXPECT_NEAR(m->period_px, p, kRelativeTolerance * p) << period << " px at " << angle << " deg";
      EXPECT_LT(m->spread_px, kRelativeTolerance * p) << "a flat surface: every block reads the same period";
      EXPECT_EQ(m->blocks, 10);  // 160 rows in blocks of 16
      EXPECT_EQ(m->rows, 160);
      if (angle == 10.0 && period == 5.5) continue;
      EXPECT_NEAR(GridTurnDeg(*m), angle, 0.1) << period << " px at " << angle << " deg";
      const double tan_angle = std::tan(angle * M_PI / 180);
      EXPECT_NEAR(RowOffsetPerPeriodPx(*m), p * tan_angle, p * (std::tan((angle + 0.1) * M_PI / 180) - tan_angle))
          << period << " px at " << angle << " deg";
    }
}

// The lit mask of the runtime (9 x 9 windows) leaves the centres of a long
// period's cells unlit: the runs join across them, and every row counts.
TEST(GridPeriod, JoinsTheUnlitCentresOfALongPeriodsCells) {
  const SyntheticPairSpec spec = Grid(31.0, 2.6);
  SyntheticPairSpec dark = spec;
  dark.ambient_dn = 0;  // lines on black: nothing but the lines is lit
  const SyntheticPair lines = RenderSyntheticPair(dark);
  const cv::Mat lit = LitMask(lines.left, 12);
  ASSERT_LT(cv::countNonZero(lit), lit.total() * 0.9) << "the cells' centres are not lit";
  const auto m = MeasureGridPeriodPx(lines.left, lit);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->period_px, AlongRowPeriodPx(spec), kRelativeTolerance * AlongRowPeriodPx(spec));
  EXPECT_EQ(m->rows, 160);
}

// The lines' width for their period, sigma / P, against the renderer's
// (lines of 90 DN over 40: no pixel saturates). Tolerance 0.0075: over eight
// noise seeds (2 DN) of each case, the reading's bias is at most 0.0008 and
// its spread at most 0.0022 (sigma 0.8 px at P = 20 px, 10 deg: the second
// harmonic nearly as strong as the first, their ratio's logarithm small),
// so three spreads and the bias (the eight cases below among 32 so
// measured). Up to sigma / P ~0.28; above ~0.3 the
// second harmonic sinks into the noise and the reading is low or missing
// (grid_line_width.h).
TEST(GridLineWidth, MeasuresTheAnalyticWidth) {
  // (sigma, P) px: sigma / P from 0.04 to 0.275, each period twice.
  const std::vector<std::pair<double, double>> cases = {{0.8, 6.0},   {1.6, 6.0},   {1.1, 8.0},  {2.2, 8.0},
                                                        {1.1, 12.15}, {2.2, 12.15}, {0.8, 20.0}, {1.6, 20.0}};
  for (const auto& [sigma, period] : cases)
    for (double angle : {2.6, 10.0}) {
      SyntheticPairSpec spec = Grid(period, angle);
      spec.grid_sigma_px = sigma;
      spec.grid_amplitude_dn = 90;
      const SyntheticPair pair = RenderSyntheticPair(spec);
      const auto m = MeasureGridPeriodPx(pair.left, AllLit(pair.left));
      ASSERT_TRUE(m);
      EXPECT_NEAR(m->line_sigma_over_period, sigma / period, 0.0075)
          << "sigma " << sigma << " px, P " << period << " px, " << angle << " deg";
    }
}

// Saturated crossings (lines of 150 DN over 40: where two cross, the sum
// clips at 255) are left out with half a period either side: a clipped peak
// would read wider. Same tolerance, on the cases a saturated grid still
// leaves stretches of four periods between crossings (2.6 deg; sigma / P
// up to 0.2). Without the stretches, every row of these images has a
// clipped crossing somewhere.
TEST(GridLineWidth, LeavesSaturatedLinesOut) {
  for (double sigma : {0.8, 1.1, 1.6})
    for (double period : {8.0, 12.15}) {
      SyntheticPairSpec spec = Grid(period, 2.6);
      spec.grid_sigma_px = sigma;
      const SyntheticPair pair = RenderSyntheticPair(spec);
      double max_dn = 0;
      cv::minMaxLoc(pair.left, nullptr, &max_dn);
      ASSERT_EQ(max_dn, 255) << "the crossings saturate";
      const auto m = MeasureGridPeriodPx(pair.left, AllLit(pair.left));
      ASSERT_TRUE(m);
      EXPECT_NEAR(m->line_sigma_over_period, sigma / period, 0.0075) << "sigma " << sigma << " px, P " << period;
    }
}

// Only the lit part of the image counts: rows outside it are not used, and
// a part too small for min_blocks gives no measurement.
TEST(GridPeriod, ReadsOnlyTheLitRegion) {
  const SyntheticPairSpec spec = Grid(9.3, 2.6);
  const SyntheticPair pair = RenderSyntheticPair(spec);
  cv::Mat lit = cv::Mat::zeros(pair.left.size(), CV_8UC1);
  lit(cv::Rect(100, 40, 200, 64)).setTo(255);  // rows 40..103: blocks 2..6
  const auto m = MeasureGridPeriodPx(pair.left, lit);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->period_px, AlongRowPeriodPx(spec), kRelativeTolerance * AlongRowPeriodPx(spec));
  EXPECT_EQ(m->rows, 64);
  EXPECT_EQ(m->blocks, 5);
  cv::Mat small = cv::Mat::zeros(pair.left.size(), CV_8UC1);
  small(cv::Rect(100, 0, 200, 32)).setTo(255);  // two blocks
  EXPECT_FALSE(MeasureGridPeriodPx(pair.left, small));
  cv::Mat narrow = cv::Mat::zeros(pair.left.size(), CV_8UC1);
  narrow(cv::Rect(100, 0, 40, 160)).setTo(255);  // runs shorter than min_run_px
  const auto none = MeasureGridPeriodPx(pair.left, narrow);
  EXPECT_FALSE(none);
}

// Without the lasers (ambient light on a weakly textured surface) there is
// no period to read.
TEST(GridPeriod, FindsNoneWithoutTheGrid) {
  SyntheticPairSpec spec = Grid(8.0, 2.6);
  spec.laser_on = false;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  EXPECT_FALSE(MeasureGridPeriodPx(pair.left, AllLit(pair.left)));
}

// A surface whose period differs between its halves (turned differently
// towards the camera): the median is one of the two, and the spread says
// the surface was not one plane facing the camera.
TEST(GridPeriod, SpreadShowsTwoPeriods) {
  const SyntheticPair a = RenderSyntheticPair(Grid(8.0, 2.6)), b = RenderSyntheticPair(Grid(10.0, 2.6));
  cv::Mat left = a.left.clone();
  b.left(cv::Rect(0, 64, 400, 96)).copyTo(left(cv::Rect(0, 64, 400, 96)));  // 4 blocks of 8 px, 6 of 10 px
  const auto m = MeasureGridPeriodPx(left, AllLit(left));
  ASSERT_TRUE(m);
  const double ten = 10.0 / std::cos(2.6 * M_PI / 180);
  EXPECT_NEAR(m->period_px, ten, kRelativeTolerance * ten);
  EXPECT_GT(m->spread_px, 0.5);  // quartiles on both sides: (10.01 - 8.01) / 2 ~ 1
}

TEST(GridPeriodKeys, TheDefaultGridsPeriodGivesTheDefaults) {
  // The simulator's default grid reads 8.07-8.46 px on its scenes
  // (docs/reconstruct.md); anything that rounds to 8 px.
  for (double period : {7.6, 7.96, 8.0, 8.4}) {
    MatchOptions o;
    const std::vector<GridPeriodKey> keys = SetGridPeriodKeys(period, &o);
    ASSERT_EQ(keys.size(), 5u);
    // `before` is the defaults' value (o started as them); the fields are
    // set to `value` (ALongerPeriodScalesTheKeysByTheDocumentedRules).
    for (const GridPeriodKey& k : keys) EXPECT_EQ(k.value, k.before) << k.key << " at " << period << " px";
  }
}

TEST(GridPeriodKeys, ALongerPeriodScalesTheKeysByTheDocumentedRules) {
  MatchOptions o;
  const std::vector<GridPeriodKey> keys = SetGridPeriodKeys(12.15, &o);  // 12 px
  EXPECT_EQ(o.grid_half_period_px, kMaxGridHalfPeriodPx);                // P / 2, at most 4 px
  EXPECT_EQ(o.line_index.max_shift_px, 18);                              // 1.5 P
  EXPECT_EQ(o.line_index.window_half_height_px, 6);                      // ceil((P - 1) / 2)
  EXPECT_EQ(o.line_index.footprint_gap_px, 12);                          // P
  EXPECT_EQ(o.grid_line.radius_px, 5);  // ceil(P / 2) + 1 = 7 widens it: not applied (below)
  EXPECT_EQ(keys[1].key, "line_index_max_shift_px");
  EXPECT_EQ(keys[1].before, 12);
  EXPECT_NO_THROW(o.Check());
  MatchOptions longest;
  SetGridPeriodKeys(kMaxGridPeriodPx, &longest);
  EXPECT_EQ(longest.line_index.footprint_gap_px, 16);  // its limit
  EXPECT_NO_THROW(longest.Check()) << "every key within its range at the longest period served";
  MatchOptions shortest;
  SetGridPeriodKeys(kMinGridPeriodPx, &shortest);
  EXPECT_NO_THROW(shortest.Check());
  EXPECT_EQ(shortest.line_index.window_half_height_px, 4) << "never below the default";
  EXPECT_EQ(shortest.grid_half_period_px, 1.5) << "P / 2 below the cap";
}

// The distinctness shift is P / 2 up to the default grid's 4 px and 4 px
// above: never longer than the defaults' (grid_period_options.h).
TEST(GridPeriodKeys, TheHalfPeriodKeyStopsAtTheDefaultGrids) {
  EXPECT_EQ(kMaxGridHalfPeriodPx, MatchOptions{}.grid_half_period_px);
  for (const auto& [period_px, half_px] : std::vector<std::pair<double, double>>{
           {5.8, 3.0}, {7.0, 3.5}, {8.2, 4.0}, {9.0, 4.0}, {12.7, 4.0}, {30.0, 4.0}}) {
    MatchOptions o;
    SetGridPeriodKeys(period_px, &o);
    EXPECT_EQ(o.grid_half_period_px, half_px) << period_px << " px";
  }
}

// grid_line_radius_px follows ceil(P / 2) + 1 only where that does not
// widen it: the plate's no_grid_line share did not tell where widening
// helps (grid_period_options.h), so a wider value is only suggested.
TEST(GridPeriodKeys, TheGridLineRadiusIsNarrowedByTheRuleButNotWidened) {
  const auto radius_key = [](const std::vector<GridPeriodKey>& keys) {
    const auto it =
        std::find_if(keys.begin(), keys.end(), [](const GridPeriodKey& k) { return k.key == "grid_line_radius_px"; });
    EXPECT_NE(it, keys.end());
    return it == keys.end() ? GridPeriodKey{} : *it;
  };
  struct Case {
    double period_px;
    int radius_before_px;
    int radius_after_px;
    double suggested_px;  // rule_not_applied
  };
  for (const Case& c : std::vector<Case>{{12.15, 5, 5, 7},  // the 34-line grating: 7 suggested, 5 kept
                                         {11.37, 5, 5, 7},  // the ring's median period
                                         {12.7, 6, 6, 8},   // widening by any step is withheld
                                         {12.15, 7, 7, 0},  // the rule's own value: unchanged
                                         {12.15, 9, 7, 0},  // wider than the rule: narrowed to it
                                         {8.07, 5, 5, 0},   // the default grid: the default
                                         {kMaxGridPeriodPx, 5, 5, 22}}) {
    MatchOptions o;
    o.grid_line.radius_px = c.radius_before_px;
    const GridPeriodKey k = radius_key(SetGridPeriodKeys(c.period_px, &o));
    const std::string at = std::to_string(c.period_px) + " px from " + std::to_string(c.radius_before_px);
    EXPECT_EQ(o.grid_line.radius_px, c.radius_after_px) << at;
    EXPECT_EQ(k.value, c.radius_after_px) << at;
    EXPECT_EQ(k.before, c.radius_before_px) << at;
    EXPECT_EQ(k.rule_not_applied, c.suggested_px) << at;
  }
}

TEST(GridPeriodKeys, APeriodNearAHalfPixelNamesTheOtherRounding) {
  EXPECT_EQ(OtherRoundedPeriodPx(12.46), 13);  // rounds to 12
  EXPECT_EQ(OtherRoundedPeriodPx(12.55), 12);  // rounds to 13
  EXPECT_EQ(OtherRoundedPeriodPx(12.74), 0);
  EXPECT_EQ(OtherRoundedPeriodPx(12.39), 0);
  EXPECT_EQ(OtherRoundedPeriodPx(8.07), 0);
  EXPECT_EQ(OtherRoundedPeriodPx(7.5), 7) << "lround takes 7.5 to 8";
}

TEST(GridPeriodKeys, RefusesAPeriodTheKeysCannotServe) {
  MatchOptions o;
  EXPECT_THROW(SetGridPeriodKeys(2.9, &o), InputError);
  EXPECT_THROW(SetGridPeriodKeys(42.6, &o), InputError);
  EXPECT_THROW(SetGridPeriodKeys(std::nan(""), &o), InputError);
  EXPECT_EQ(o.grid_half_period_px, MatchOptions{}.grid_half_period_px) << "left as it was";
}

}  // namespace
}  // namespace stereorig
