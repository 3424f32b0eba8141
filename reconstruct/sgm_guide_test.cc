// The guided full-resolution search: GuideFromCoarse against analytic maps,
// SgmMatchGuided against the synthetic pair's true disparity and against
// the whole-range SgmMatch.
#include "reconstruct/sgm_guide.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "reconstruct/census_sgm.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

TEST(GuideFromCoarse, UpsamplesAndInterpolatesGapsOfAPlane) {
  // A half-resolution plane d = 20 + 0.1 x + 0.05 y (half-res px) over a
  // region starting at (10, 6), with a gap inside a row, a gap at a row's
  // start and a row without any match. Linear interpolation is exact on a
  // plane, so every guide value is twice the plane at its half-res pixel,
  // to within the rounding (0.5 px) and the float sums (1e-4 px).
  const cv::Rect coarse_region(10, 6, 40, 30);
  auto plane = [](int cx, int cy) { return 20.0 + 0.1 * cx + 0.05 * cy; };
  cv::Mat coarse(coarse_region.size(), CV_32FC1);
  for (int y = 0; y < coarse.rows; ++y)
    for (int x = 0; x < coarse.cols; ++x) coarse.at<float>(y, x) = float(plane(x, y));
  for (int x = 5; x < 25; ++x) coarse.at<float>(3, x) = kNan;  // a gap inside a row
  for (int x = 0; x < 12; ++x)  // at the row's start (removed blobs are inf): the nearest value
    coarse.at<float>(8, x) = std::numeric_limits<float>::infinity();
  for (int x = 0; x < coarse.cols; ++x) coarse.at<float>(15, x) = kNan;  // a whole row
  const cv::Rect region(22, 14, 60, 40);                                 // full-res px, inside 2 * coarse_region
  const cv::Mat guide = GuideFromCoarse(coarse, coarse_region, region, -999);
  ASSERT_EQ(guide.type(), CV_16SC1);
  ASSERT_EQ(guide.size(), region.size());
  for (int y = 0; y < region.height; ++y)
    for (int x = 0; x < region.width; ++x) {
      const int cx = (region.x + x) / 2 - coarse_region.x, cy = (region.y + y) / 2 - coarse_region.y;
      // Row 8's start takes its first match (x = 12): the plane there.
      const double expected = 2 * (cy == 8 && cx < 12 ? plane(12, cy) : plane(cx, cy));
      ASSERT_NEAR(guide.at<int16_t>(y, x), expected, 0.5 + 1e-4) << x << "," << y;
    }
}

TEST(GuideFromCoarse, FallsBackWithoutAnyMatch) {
  const cv::Mat coarse(10, 10, CV_32FC1, cv::Scalar(kNan));
  const cv::Mat guide = GuideFromCoarse(coarse, cv::Rect(0, 0, 10, 10), cv::Rect(2, 2, 12, 12), 77);
  EXPECT_EQ(cv::countNonZero(guide != 77), 0);
}

struct GuidedCase {
  SyntheticPair pair;
  CensusImage left, right;
  cv::Rect region;
};

// The simulator's laser grid on a slanted plane (disparity 40-62 px over the
// region) and a range of 96 disparities, much wider than a guided window.
GuidedCase MakeCase() {
  SyntheticPairSpec spec;
  spec.width = 320;
  spec.height = 120;
  GuidedCase c{RenderSyntheticPair(spec), {}, {}, cv::Rect(80, 8, 232, 104)};
  c.left = CensusTransform(c.pair.left, 0, spec.height, 1, 2, 3);
  c.right = CensusTransform(c.pair.right, 0, spec.height, 1, 2, 3);
  return c;
}

constexpr int kMinDisparity = 10, kNumDisparities = 96, kRadius = 15;

// A guide off the truth by a pseudo-random integer in [-max_off, max_off]
// that changes every few pixels (windows of neighbours differ, in both
// directions): the truth stays inside every window when max_off < kRadius.
cv::Mat JitteredGuide(const GuidedCase& c, int max_off, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> off(-max_off, max_off);
  cv::Mat guide(c.region.size(), CV_16SC1);
  for (int y = 0; y < guide.rows; ++y) {
    int o = off(rng);
    for (int x = 0; x < guide.cols; ++x) {
      if (rng() % 4 == 0) o = off(rng);
      guide.at<int16_t>(y, x) =
          int16_t(std::lround(c.pair.true_disparity_px.at<double>(c.region.y + y, c.region.x + x)) + o);
    }
  }
  return guide;
}

TEST(SgmMatchGuided, EqualsTheWholeRangeSearchWhereTheTruthIsInsideTheWindow) {
  const GuidedCase c = MakeCase();
  SgmOptions o;
  const cv::Mat full = SgmMatch(c.left, c.right, c.region, kMinDisparity, kNumDisparities, o);
  const cv::Mat guided =
      SgmMatchGuided(c.left, c.right, c.region, JitteredGuide(c, 8, 3), kRadius, kMinDisparity, kNumDisparities, o);
  int full_valid = 0, both = 0, same = 0, guided_wrong = 0;
  for (int y = 0; y < full.rows; ++y)
    for (int x = 0; x < full.cols; ++x) {
      const float f = full.at<float>(y, x), g = guided.at<float>(y, x);
      const double truth = c.pair.true_disparity_px.at<double>(c.region.y + y, c.region.x + x);
      full_valid += !std::isnan(f);
      if (!std::isnan(g)) guided_wrong += std::abs(g - truth) > 1.0;
      if (std::isnan(f) || std::isnan(g)) continue;
      ++both;
      same += std::abs(f - g) <= 0.05f;
    }
  std::printf("full valid %d, both %d, equal %d, guided off the truth by > 1 px %d\n", full_valid, both, same,
              guided_wrong);
  EXPECT_GT(full_valid, 0.8 * full.total());
  EXPECT_GT(both, 0.98 * full_valid);
  EXPECT_GT(same, 0.98 * both);
  EXPECT_LT(guided_wrong, 0.002 * full.total());
}

TEST(SgmMatchGuided, SimdAndScalarAgreeUnderShiftingWindows) {
  if (!SgmSimdAvailable()) GTEST_SKIP() << "this build has no AVX2 kernels";
  const GuidedCase c = MakeCase();
  // Offsets up to 20 px: some windows miss the truth, so rejections and
  // window-edge minima are exercised too.
  const cv::Mat guide = JitteredGuide(c, 20, 9);
  for (const int paths : {3, 4}) {
    SgmOptions o;
    o.num_paths = paths;
    const cv::Mat simd = SgmMatchGuided(c.left, c.right, c.region, guide, kRadius, kMinDisparity, kNumDisparities, o);
    o.simd = false;
    const cv::Mat scalar = SgmMatchGuided(c.left, c.right, c.region, guide, kRadius, kMinDisparity, kNumDisparities, o);
    int differ = 0;
    for (int y = 0; y < simd.rows; ++y)
      for (int x = 0; x < simd.cols; ++x) {
        const float a = simd.at<float>(y, x), b = scalar.at<float>(y, x);
        differ += !(a == b || (std::isnan(a) && std::isnan(b)));
      }
    EXPECT_EQ(differ, 0) << "paths " << paths;
  }
}

// The 4-path SGM holds its forward sums a block of rows at a time, run
// again from the top->bottom path's state saved at each block's start
// (census_sgm.cc). One block of all rows restores nothing: the forward
// paths run once, top to bottom, as with the whole region's sums kept. Any
// other blocking must give the same disparities bit for bit, with constant
// windows and with windows that shift between rows (the block's first row
// steps from the previous row's window), on both kernel sets.
TEST(SgmMatchGuided, TheForwardSumsBlockingDoesNotChangeTheResult) {
  const GuidedCase c = MakeCase();
  const cv::Mat guide = JitteredGuide(c, 20, 11);
  auto differing = [](const cv::Mat& a, const cv::Mat& b) {
    int n = 0;
    for (int y = 0; y < a.rows; ++y)
      for (int x = 0; x < a.cols; ++x) {
        const float u = a.at<float>(y, x), v = b.at<float>(y, x);
        n += !(u == v || (std::isnan(u) && std::isnan(v)));
      }
    return n;
  };
  std::vector<bool> kernels{false};
  if (SgmSimdAvailable()) kernels.push_back(true);
  for (const bool simd : kernels)
    for (const bool guided : {false, true}) {
      SgmOptions o;
      o.simd = simd;
      auto match = [&](int block_rows) {
        o.block_rows = block_rows;
        return guided ? SgmMatchGuided(c.left, c.right, c.region, guide, kRadius, kMinDisparity, kNumDisparities, o)
                      : SgmMatch(c.left, c.right, c.region, kMinDisparity, kNumDisparities, o);
      };
      const cv::Mat one_block = match(c.region.height);
      // Not vacuous: most of the plane matches.
      EXPECT_GT(cv::countNonZero(one_block == one_block), 0.5 * one_block.total());
      for (const int block_rows : {1, 2, 5, 7, 13, 0})
        EXPECT_EQ(differing(match(block_rows), one_block), 0)
            << "block_rows " << block_rows << " guided " << guided << " simd " << simd;
    }
}

}  // namespace
}  // namespace stereorig
