// The matcher against ground truth: analytically rendered pairs with a known
// sub-pixel disparity field (synthetic_pair.h), and OpenCV's StereoSGBM run
// on the same pairs as the independent reference.
#include "reconstruct/matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "calib/core/input_error.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

struct ErrorStats {
  int valid = 0, total = 0;
  double mean = 0, rms = 0, max_abs = 0;
  // Mean error of the pixels whose true disparity has its fractional part in
  // [i/10, (i+1)/10): a peak-locked matcher shows a sawtooth here.
  double bin_mean[10] = {};
  int bin_count[10] = {};
  double fill() const { return total ? double(valid) / total : 0; }
  double worst_bin() const {
    double w = 0;
    for (int i = 0; i < 10; ++i)
      if (bin_count[i] > 20) w = std::max(w, std::abs(bin_mean[i] - mean));
    return w;
  }
};

// Statistics over the inner area: a border of `margin` px is excluded (the
// windows are not defined there), and so are the left pixels whose true match
// lies outside the right image (nothing can be measured there).
ErrorStats Score(const MatchResult& m, const SyntheticPair& pair, int margin) {
  ErrorStats s;
  double sum = 0, sum2 = 0;
  for (int y = margin; y < pair.left.rows - margin; ++y)
    for (int x = margin; x < pair.left.cols - margin; ++x) {
      if (x - pair.true_disparity_px.at<double>(y, x) < margin) continue;
      ++s.total;
      const float d = m.disparity_px.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const double truth = pair.true_disparity_px.at<double>(y, x);
      const double e = d - truth;
      ++s.valid;
      sum += e;
      sum2 += e * e;
      s.max_abs = std::max(s.max_abs, std::abs(e));
      const int bin = std::min(9, int((truth - std::floor(truth)) * 10));
      s.bin_mean[bin] += e;
      ++s.bin_count[bin];
    }
  if (s.valid) {
    s.mean = sum / s.valid;
    s.rms = std::sqrt(sum2 / s.valid);
  }
  for (int i = 0; i < 10; ++i)
    if (s.bin_count[i]) s.bin_mean[i] /= s.bin_count[i];
  return s;
}

void Print(const char* name, const ErrorStats& s) {
  std::printf("%-22s fill %.3f  mean %+.4f px  rms %.4f px  max %.3f px  peak-lock (worst bin - mean) %.4f px\n", name,
              s.fill(), s.mean, s.rms, s.max_abs, s.worst_bin());
  std::printf("%-22s bins:", "");
  for (int i = 0; i < 10; ++i) std::printf(" %+.3f", s.bin_mean[i]);
  std::printf("\n");
}

// The precision floor of a window fit under the injected noise: for a shift
// estimated from n samples with gradients g_i and white noise sigma on both
// images, var(d) ~= 2 sigma^2 / sum g_i^2 (the Cramer-Rao bound of the
// translation-only model). Returned as the RMS over the inner area.
double NoiseFloorRms(const SyntheticPair& pair, const SubpixelOptions& w, double sigma, int margin) {
  cv::Mat gx;
  cv::Sobel(pair.left_clean, gx, CV_64F, 1, 0, 1);  // central difference * 2
  gx *= 0.5;
  double sum_var = 0;
  int n = 0;
  for (int y = margin; y < pair.left.rows - margin; ++y)
    for (int x = margin; x < pair.left.cols - margin; ++x) {
      double g2 = 0;
      for (int v = -w.half_height_px; v <= w.half_height_px; ++v)
        for (int u = -w.half_width_px; u <= w.half_width_px; ++u) g2 += std::pow(gx.at<double>(y + v, x + u), 2);
      sum_var += 2 * sigma * sigma / g2;
      ++n;
    }
  return std::sqrt(sum_var / n);
}

MatchOptions Options(MatcherKind kind) {
  MatchOptions o;
  o.matcher = kind;
  o.min_disparity_px = 24;
  o.num_disparities = 64;
  return o;
}

constexpr int kMargin = 12;

TEST(Matcher, SlantedLaserGridPlaneIsAccurateAndNotPeakLocked) {
  SyntheticPairSpec spec;  // 320x240, d = 40 + 0.04 x + 0.015 y, noise 2 DN
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const MatchOptions ours = Options(MatcherKind::kCensusSgm);
  const ErrorStats s = Score(Match(pair.left, pair.right, ours), pair, kMargin);
  // SGBM with its own sub-pixel step (a parabola on its cost curve).
  MatchOptions sgbm_own = Options(MatcherKind::kOpenCvSgbm3Way);
  sgbm_own.intensity_refinement = false;
  const ErrorStats sgbm = Score(Match(pair.left, pair.right, sgbm_own), pair, kMargin);
  MatchOptions no_lk = ours;
  no_lk.intensity_refinement = false;
  const ErrorStats cost_fit = Score(Match(pair.left, pair.right, no_lk), pair, kMargin);
  Print("census_sgm", s);
  Print("census_sgm (cost fit)", cost_fit);
  Print("opencv_sgbm_3way", sgbm);
  const double floor = NoiseFloorRms(pair, ours.subpixel, spec.noise_sigma_dn, kMargin);
  std::printf("noise floor (CRLB, 2 DN on both images): %.4f px rms\n", floor);

  // A smooth, fully lit plane: nearly every pixel must match.
  EXPECT_GT(s.fill(), 0.97);
  // No gross errors: the coarse level must pick the right grid line.
  EXPECT_LT(s.max_abs, 0.5);
  // Precision: the noise floor plus the window's model error. The window
  // is fitted with a pure shift, but across a 0.04 px/px disparity gradient
  // the right view is 4% compressed; rendered without noise that alone gives
  // 0.027 px rms (measured), so noise + model ~ sqrt(0.0145^2 + 0.027^2) =
  // 0.031 px. The fronto-parallel test below checks the noise part alone.
  EXPECT_LT(s.rms, std::hypot(1.2 * floor, 0.03));
  // Bias: the mean over ~60k pixels; its statistical scatter is ~rms/sqrt(n
  // independent windows ~ 1000) < 0.005 px, so 0.01 px is a real bias.
  EXPECT_LT(std::abs(s.mean), 0.01);
  // Peak locking: every fractional-disparity bin within 0.01 px of the mean
  // (each bin holds ~6k pixels; its scatter is < 0.005 px).
  EXPECT_LT(s.worst_bin(), 0.01);
  // And clearly better than both cost-curve fits on the same pair.
  EXPECT_LT(s.worst_bin(), 0.5 * cost_fit.worst_bin());
  EXPECT_LT(s.rms, 0.5 * sgbm.rms);
}

TEST(Matcher, FrontoParallelPlaneReachesTheNoiseFloor) {
  SyntheticPairSpec spec;
  spec.du = spec.dv = 0;
  spec.d0_px = 43.37;
  spec.seed = 3;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const MatchOptions o = Options(MatcherKind::kCensusSgm);
  const ErrorStats s = Score(Match(pair.left, pair.right, o), pair, kMargin);
  const double floor = NoiseFloorRms(pair, o.subpixel, std::hypot(spec.noise_sigma_dn, 1 / std::sqrt(12.0)), kMargin);
  Print("census_sgm flat", s);
  std::printf("noise floor (CRLB, 2 DN + 8-bit rounding): %.4f px rms\n", floor);
  EXPECT_GT(s.fill(), 0.97);
  // Gauss-Newton reaches the Cramer-Rao floor within 40%: the floor ignores
  // the gain/offset parameters, and the disparity slopes the window is warped
  // with come from the noisy integer-level field (~0.005 px/px over 9x9).
  EXPECT_LT(s.rms, 1.4 * floor);
  // A constant true disparity: the bias is the mean error; scatter of the
  // mean < 0.015 / sqrt(~1000 windows) ~ 0.0005 px.
  EXPECT_LT(std::abs(s.mean), 0.003);
}

TEST(Matcher, CoarseToFineFindsTheRightLineToo) {
  SyntheticPairSpec spec;
  spec.seed = 2;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  MatchOptions o = Options(MatcherKind::kCensusSgm);
  o.pyramid_levels = 1;
  const ErrorStats s = Score(Match(pair.left, pair.right, o), pair, kMargin);
  Print("census_sgm levels=1", s);
  EXPECT_GT(s.fill(), 0.97);
  EXPECT_LT(s.max_abs, 0.5);
}

TEST(Matcher, CheaperBandPassesStillBracketTheTruth) {
  // The occupied-band pass with 3 paths and on every other half-resolution
  // row: the band it finds must still hold the whole plane (true d 40..56
  // px) in a 96 px range, else pixels go unmatched or a grid period off
  // (~8 px, far above the 0.5 px bound). Same bounds as the slanted-plane
  // test above, whose pair this is.
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  for (const auto& [paths, row_step] : {std::pair{3, 1}, std::pair{4, 2}, std::pair{3, 2}}) {
    MatchOptions o = Options(MatcherKind::kCensusSgm);
    o.min_disparity_px = 8;
    o.num_disparities = 96;
    o.band_sgm_paths = paths;
    o.band_row_step = row_step;
    const ErrorStats s = Score(Match(pair.left, pair.right, o), pair, kMargin);
    Print("census_sgm cheap band", s);
    EXPECT_GT(s.fill(), 0.97) << paths << " paths, row step " << row_step;
    EXPECT_LT(s.max_abs, 0.5) << paths << " paths, row step " << row_step;
  }
}

TEST(Matcher, ReportsTheDisparitiesItSearched) {
  // The slanted plane's true disparities: 40 + 0.04 x + 0.015 y over
  // 320 x 240, 40 to 56.3 px. The occupied band the half-resolution pass
  // finds must hold them and lie inside the 96 px given; without the
  // band pass, and with OpenCV SGBM, the whole given range is searched.
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  double truth_lo = 1e9, truth_hi = -1e9;
  cv::minMaxLoc(pair.true_disparity_px, &truth_lo, &truth_hi);
  ASSERT_GT(truth_hi - truth_lo, 16);  // the slanted plane, not a flat one
  MatchOptions o = Options(MatcherKind::kCensusSgm);
  o.min_disparity_px = 8;
  o.num_disparities = 96;
  const MatchResult banded = Match(pair.left, pair.right, o);
  std::printf("band [%d, %d) for truth [%.2f, %.2f]\n", banded.searched_min_disparity_px,
              banded.searched_min_disparity_px + banded.searched_num_disparities, truth_lo, truth_hi);
  EXPECT_LE(banded.searched_min_disparity_px, truth_lo);
  EXPECT_GE(banded.searched_min_disparity_px + banded.searched_num_disparities - 1, truth_hi);
  EXPECT_GE(banded.searched_min_disparity_px, o.min_disparity_px);
  // Measured [8, 72): narrower than the range, though not by much on this
  // synthetic grid (the coarse pass also matches it whole periods off).
  EXPECT_LT(banded.searched_num_disparities, o.num_disparities);
  o.narrow_range = false;
  const MatchResult whole = Match(pair.left, pair.right, o);
  EXPECT_EQ(whole.searched_min_disparity_px, 8);
  EXPECT_EQ(whole.searched_num_disparities, 96);
  for (const MatcherKind kind : {MatcherKind::kOpenCvSgbm3Way, MatcherKind::kOpenCvSgbm3WayStandalone}) {
    o.matcher = kind;
    o.narrow_range = true;
    const MatchResult sgbm = Match(pair.left, pair.right, o);
    EXPECT_EQ(sgbm.searched_min_disparity_px, 8);
    EXPECT_EQ(sgbm.searched_num_disparities, 96);
  }
}

// A range wider than the images (a rig whose working distance the options
// miss by far): OpenCV's SGBM, left to itself, ends the process there
// (OpenCV 4.6 asserts in a destructor when no column has its whole range in
// the image). Both SGBM pipelines find nothing instead, and say so.
TEST(Matcher, SgbmWithARangeWiderThanTheImageFindsNothing) {
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  for (const MatcherKind kind : {MatcherKind::kOpenCvSgbm3Way, MatcherKind::kOpenCvSgbm3WayStandalone}) {
    MatchOptions o = Options(kind);
    o.min_disparity_px = 0;
    o.num_disparities = pair.left.cols + 16;  // every column's range reaches past the right image's left edge
    const MatchResult m = Match(pair.left, pair.right, o);
    int finite = 0;
    for (int y = 0; y < m.disparity_px.rows; ++y)
      for (int x = 0; x < m.disparity_px.cols; ++x) finite += std::isfinite(m.disparity_px.at<float>(y, x));
    EXPECT_EQ(finite, 0) << MatcherKindName(kind);
    EXPECT_EQ(cv::countNonZero(m.status == uint8_t(PixelStatus::kNoSgmMatch)), pair.left.rows * pair.left.cols)
        << MatcherKindName(kind);
  }
}

TEST(Matcher, RoiAndRangeAreHonoured) {
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  MatchOptions o = Options(MatcherKind::kCensusSgm);
  o.roi = cv::Rect(100, 60, 120, 80);
  const MatchResult m = Match(pair.left, pair.right, o);
  int inside = 0;
  for (int y = 0; y < pair.left.rows; ++y)
    for (int x = 0; x < pair.left.cols; ++x) {
      const bool valid = std::isfinite(m.disparity_px.at<float>(y, x));
      if (!o.roi.contains(cv::Point(x, y))) {
        ASSERT_FALSE(valid) << "outside the ROI at " << x << "," << y;
      } else if (valid) {
        ++inside;
        EXPECT_GT(m.confidence.at<float>(y, x), 0.5f);
      }
    }
  EXPECT_GT(inside, 0.95 * o.roi.area());
  // A range that excludes the truth (40..50 px): every output stays inside
  // the range. (It is NOT empty: a grid shifted by whole periods looks almost
  // the same, so the a-priori range is what picks the right line. The
  // runtime derives it from the measurement volume for that reason.)
  o.roi = {};
  o.min_disparity_px = 60;
  o.num_disparities = 32;
  const MatchResult wrong = Match(pair.left, pair.right, o);
  for (int y = 0; y < pair.left.rows; ++y)
    for (int x = 0; x < pair.left.cols; ++x) {
      const float d = wrong.disparity_px.at<float>(y, x);
      if (std::isfinite(d)) {
        ASSERT_TRUE(d >= 60 && d <= 91) << d;
      }
    }
}

TEST(Matcher, PassiveWeakTextureFillsLessThanActive) {
  SyntheticPairSpec spec;
  spec.laser_on = false;
  const SyntheticPair passive = RenderSyntheticPair(spec);
  MatchOptions o = Options(MatcherKind::kCensusSgm);
  o.grid_line.enabled = false;  // as passive runs have it: no grid, no line to support a point
  const ErrorStats s = Score(Match(passive.left, passive.right, o), passive, kMargin);
  Print("census_sgm passive", s);
  EXPECT_LT(s.fill(), 0.9);  // the weak texture alone cannot carry every pixel
}

// The first sub-pixel pass on every 2nd / 3rd column only, the pixels
// between interpolated along the row (MatchOptions::subpixel_column_step):
// against the truth, as accurate as every column. Surface fit off, so the
// interpolated values themselves are scored (the fit would average them).
TEST(Matcher, SkippedColumnsStayAtTheNoiseFloorOnTheTruePlane) {
  SyntheticPairSpec spec;  // 320x240, d = 40 + 0.04 x + 0.015 y, noise 2 DN
  const SyntheticPair pair = RenderSyntheticPair(spec);
  MatchOptions o = Options(MatcherKind::kCensusSgm);
  o.surface_fit.enabled = false;
  const double floor = NoiseFloorRms(pair, o.subpixel, spec.noise_sigma_dn, kMargin);
  for (const int step : {2, 3}) {
    o.subpixel_column_step = step;
    const MatchResult m = Match(pair.left, pair.right, o);
    const ErrorStats s = Score(m, pair, kMargin);
    Print(step == 2 ? "census_sgm step 2" : "census_sgm step 3", s);
    // The bounds of SlantedLaserGridPlaneIsAccurateAndNotPeakLocked: an
    // interpolated value is the mean of two estimates whose windows overlap
    // it (noise no larger than one estimate's); on a plane the
    // interpolation itself is exact.
    EXPECT_GT(s.fill(), 0.97) << step;
    EXPECT_LT(s.max_abs, 0.5) << step;
    EXPECT_LT(s.rms, std::hypot(1.2 * floor, 0.03)) << step;
    EXPECT_LT(std::abs(s.mean), 0.01) << step;
    EXPECT_LT(s.worst_bin(), 0.01) << step;
  }
}

// At a silhouette (the plane ends at column 200 against a flat background)
// the skipped columns add nothing beyond what the full pass measures. The
// truth: no window centred more than twice its half width past the edge
// sees the plane (growing's shifted window, region_grow.h, reaches one
// half width further than the centred one), so no point may be there; and
// away from the edge (a half width plus a column: the windows there see only
// the plane) every point lies within 0.25 px of the plane (~15x the 2 DN
// noise's ~0.016 px rms; a point from an interpolation across the edge
// would be off by far more). Nearer the edge the windows still hold plane
// columns and every step keeps some points there: at most 10 % more than
// every column gives (measured: 722 / 755 / 723 points for steps 1 / 2 / 3,
// growing from slightly different seeds).
TEST(Matcher, SkippedColumnsDoNotReachPastASilhouette) {
  SyntheticPairSpec spec;
  SyntheticPair pair = RenderSyntheticPair(spec);
  constexpr int kEdge = 200;
  EndPlaneAtColumn(kEdge, 12, &pair);
  MatchOptions o = Options(MatcherKind::kCensusSgm);
  const int hw = o.subpixel.half_width_px;
  int full_pass_near_edge = 0;
  for (const int step : {1, 2, 3}) {
    o.subpixel_column_step = step;
    const MatchResult m = Match(pair.left, pair.right, o);
    int near_edge = 0, far_past = 0, inside = 0, off = 0;
    for (int y = kMargin; y < pair.left.rows - kMargin; ++y)
      for (int x = kMargin; x < pair.left.cols - kMargin; ++x) {
        const double truth = pair.true_disparity_px.at<double>(y, x);
        const float d = m.disparity_px.at<float>(y, x);
        if (x - truth < kMargin || !std::isfinite(d)) continue;  // as Score
        if (x >= kEdge + 2 * hw) {
          ++far_past;
        } else if (x >= kEdge) {
          ++near_edge;
        } else if (x < kEdge - hw - 1) {
          ++inside;
          off += std::abs(d - truth) > 0.25;
        }
      }
    std::printf("silhouette, step %d: %d points on the plane (%d off it), %d within %d px past the edge, %d beyond\n",
                step, inside, off, near_edge, 2 * hw, far_past);
    if (step == 1) full_pass_near_edge = near_edge;
    EXPECT_EQ(far_past, 0) << step;
    EXPECT_EQ(off, 0) << step;
    EXPECT_LE(near_edge, 1.1 * full_pass_near_edge) << step;
    // The plane's columns scored (x - d >= 12 from ~x = 54, to 195), less
    // the margins' rows: ~141 x 216 px.
    EXPECT_GT(inside, 0.97 * 141 * (pair.left.rows - 2 * kMargin)) << step;
  }
}

// The smallest images follow the options (a census window at the coarsest
// level), and smaller ones are refused as input: a 1-row pair used to reach
// OpenCV's resize to 0 px, a cv::Exception that aborted the process.
TEST(Matcher, ImagesSmallerThanTheCoarseLevelNeedsAreRefused) {
  MatchOptions o;
  o.num_disparities = 16;
  EXPECT_EQ(MinMatchImageSize(o).size, cv::Size(10, 14));  // the band pass halves columns and rows
  o.band_row_step = 2;
  EXPECT_EQ(MinMatchImageSize(o).size, cv::Size(10, 28));
  o.band_row_step = 1;
  o.narrow_range = false;
  EXPECT_EQ(MinMatchImageSize(o).size, cv::Size(5, 7));
  o.pyramid_levels = 2;
  o.census_half_width_px = 4;
  EXPECT_EQ(MinMatchImageSize(o).size, cv::Size(36, 28));
  o.matcher = MatcherKind::kOpenCvSgbm3Way;  // full resolution only
  EXPECT_EQ(MinMatchImageSize(o).size, cv::Size(1, 1));
  const MatchOptions defaults = [] {
    MatchOptions d;
    d.num_disparities = 16;
    return d;
  }();
  const cv::Mat row(1, 100, CV_8UC1, cv::Scalar(7));
  EXPECT_THROW(Match(row, row, defaults), InputError);
  const cv::Mat smallest(14, 10, CV_8UC1, cv::Scalar(7));
  EXPECT_NO_THROW(Match(smallest, smallest, defaults));
}

}  // namespace
}  // namespace stereorig
