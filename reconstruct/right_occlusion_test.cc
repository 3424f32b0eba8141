// Right-view visibility on synthetic disparity rows whose occluded zones are
// known analytically: a nearer band of disparity D_near over background D_far
// hides, in the right view, the background pixels in the (D_near - D_far) px
// just left of the band's left edge (x - D_far lands where the band's pixels
// x' - D_near do).
#include "reconstruct/right_occlusion.h"

#include "calib/core/input_error.h"
#include "reconstruct/disparity_state_testing.h"
#include "reconstruct/runtime_options.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace stereorig {
namespace {

using testing::StateOf;

bool Dropped(const DisparityState& s, int y, int x) {
  return !std::isfinite(s.disparity_px.at<float>(y, x)) &&
         s.status.at<uint8_t>(y, x) == uint8_t(PixelStatus::kOccluded);
}

// Background 20 px, a nearer band 30.5 px over x in [100, 150): the band
// lands on right columns [69.5, 119.5), so background pixel x is hidden when
// x - 20 is in it: x in [89.5, 100), whatever the margin (it widens only the
// right view's edge). Exact: no noise is added, so no tolerance.
TEST(RightOcclusion, DropsTheBackgroundZoneANearerBandHidesInTheRightView) {
  for (const double margin : {1.0, 2.0}) {
    cv::Mat d(4, 300, CV_32FC1, cv::Scalar(20.0));
    d(cv::Rect(100, 0, 50, 4)).setTo(30.5);
    DisparityState s = StateOf(d);
    const int dropped = DropRightInvisible(margin, cv::Mat(), cv::Rect(0, 0, 300, 4), &s);
    SCOPED_TRACE(margin);
    // The band's own pixels and the background right of it are seen; the
    // background left of the zone too, except the columns whose right match
    // x - 20 lies within the margin of the right image's edge (x < 20 + m).
    const int first_hidden = 90;
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 300; ++x) {
        const bool hidden = (x >= first_hidden && x < 100) || x - 20 - margin < 0;
        EXPECT_EQ(Dropped(s, y, x), hidden) << "x " << x;
      }
    EXPECT_EQ(dropped, 4 * ((100 - first_hidden) + int(std::ceil(20 + margin))));
  }
}

// A slanted surface, d = 20 + 0.4 x (the right view shrinks it to 60 %),
// with 0.1 px of disparity noise (the refined matches' noise on the
// simulator is ~0.25 px): its own pixels must not hide each other. A pixel
// k px to the right lands 0.6 k px further right and is 0.4 k px nearer; to
// land at or left of x - d noise must take 0.6 k px off its landing and it
// must still be > 1 px nearer: k = 1 needs a noise difference of 0.6 px, 4.2
// sigma of the difference (0.14 px rms) injected here.
TEST(RightOcclusion, KeepsASlantedSurface) {
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 0.1f);  // see above
  cv::Mat d(20, 400, CV_32FC1);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) = 20.f + 0.4f * x + noise(rng);
  DisparityState s = StateOf(d);
  DropRightInvisible(1.0, cv::Mat(), cv::Rect(0, 0, 400, 20), &s);
  // Only the columns matched outside the right image: x - d - 1 = 0.6 x - 21
  // is < 0 below x = 35; the noise (4 sigma: 0.4 px) moves that edge by
  // < 1 px either way, so x <= 33 is dropped and x >= 37 kept.
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) {
      if (x <= 33) {
        EXPECT_TRUE(Dropped(s, y, x)) << y << " " << x;
      } else if (x >= 37) {
        EXPECT_FALSE(Dropped(s, y, x)) << y << " " << x;
      }
    }
}

// Outside the right view: columns < 50 of the rectified right image have no
// sensor data. At d = 20 left pixel x matches x - 20; with margin 1 it is
// dropped while floor(x - 20 - 1) < 50, i.e. x < 71.
TEST(RightOcclusion, DropsMatchesOnRightColumnsWithoutData) {
  cv::Mat valid(3, 200, CV_8UC1, cv::Scalar(255));
  valid(cv::Rect(0, 0, 50, 3)).setTo(0);
  DisparityState s = StateOf(cv::Mat(3, 200, CV_32FC1, cv::Scalar(20.0)));
  EXPECT_EQ(DropRightInvisible(1.0, valid, cv::Rect(0, 0, 200, 3), &s), 3 * 71);
  for (int x = 0; x < 200; ++x) EXPECT_EQ(Dropped(s, 1, x), x < 71) << x;
  // Off: nothing touched.
  DisparityState off = StateOf(cv::Mat(3, 200, CV_32FC1, cv::Scalar(20.0)));
  EXPECT_EQ(DropRightInvisible(0.0, valid, cv::Rect(0, 0, 200, 3), &off), 0);
}

// Against the rule written plainly (every pixel right of x on its row is a
// candidate occluder, no bound on the scan, no skipping; each column of the
// edge test's range tested on its own): random rows of surfaces at random
// depths, with slopes, noise and holes, over a right view with columns
// without data (two bands, and single columns that differ from row to row,
// so that a range ending or starting on one is met: an off-by-one in the
// per-row count of such columns drops or keeps those pixels wrongly), at
// three margins. The fast scan must drop exactly the same pixels; exact
// (the same float landings), so no tolerance.
TEST(RightOcclusion, DropsExactlyWhatThePlainRuleDrops) {
  for (const double margin : {0.5, 1.0, 2.5}) {
    SCOPED_TRACE(margin);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> level(-20.f, 80.f), slope(-0.6f, 0.9f), unit(0.f, 1.f);
    std::normal_distribution<float> noise(0.f, 0.3f);
    const cv::Rect roi(7, 1, 280, 30);
    cv::Mat d(32, 300, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
    for (int y = roi.y; y < roi.y + roi.height; ++y) {
      float base = level(rng), dd_dx = slope(rng);
      for (int x = roi.x; x < roi.x + roi.width; ++x) {
        if (unit(rng) < 0.04f) base = level(rng), dd_dx = slope(rng);  // a depth step
        if (unit(rng) < 0.1f) continue;                                // a hole
        d.at<float>(y, x) = base + dd_dx * 0.1f * (x % 40) + noise(rng);
      }
    }
    cv::Mat valid(d.size(), CV_8UC1, cv::Scalar(255));
    valid(cv::Rect(0, 0, 15, d.rows)).setTo(0);
    valid(cv::Rect(120, 0, 3, d.rows)).setTo(0);
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x)
        if (unit(rng) < 0.03f) valid.at<uint8_t>(y, x) = 0;
    for (const int threads : {1, 4}) {  // the rows on one thread, or cut into chunks among several
      SCOPED_TRACE(threads);
      DisparityState s = StateOf(d);
      const int dropped = DropRightInvisible(margin, valid, roi, &s, threads);
      int expected = 0, occluded = 0;
      for (int y = roi.y; y < roi.y + roi.height; ++y)
        for (int x = roi.x; x < roi.x + roi.width; ++x) {
          const float dx = d.at<float>(y, x);
          if (!std::isfinite(dx)) continue;
          const double xr = x - dx;
          bool outside = false;
          for (int c = int(std::floor(xr - margin)); c <= int(std::floor(xr + margin)); ++c)
            outside = outside || c < 0 || c >= d.cols || !valid.at<uint8_t>(y, c);
          bool behind = false;
          for (int xo = x + 1; xo < roi.x + roi.width; ++xo) {
            const float o = d.at<float>(y, xo);
            behind = behind || (std::isfinite(o) && o > dx + 1 && xo - o <= xr);
          }
          expected += outside || behind;
          occluded += behind && !outside;
          EXPECT_EQ(Dropped(s, y, x), outside || behind) << y << " " << x;
        }
      EXPECT_EQ(dropped, expected);
      EXPECT_GT(occluded, 100);  // the rows do exercise the occlusion scan
    }
  }
}

// The mask from remap tables: columns mapping outside the sensor are 0.
TEST(RightOcclusion, ValidMaskFromRemapTables) {
  cv::Mat mx(2, 10, CV_32FC1), my(2, 10, CV_32FC1, cv::Scalar(0.5));
  for (int x = 0; x < 10; ++x) mx.col(x).setTo(x - 3.0);  // rectified x -> sensor x - 3
  const cv::Mat v = ViewValidMask(mx, my, cv::Size(5, 2));
  for (int x = 0; x < 10; ++x) EXPECT_EQ(v.at<uint8_t>(1, x), (x >= 3 && x <= 7) ? 255 : 0) << x;
}

// The runtime options file sets both new keys and rejects bad values.
TEST(RightOcclusion, OptionsFileKeys) {
  const RuntimeOptions o =
      ParseRuntimeOptions("match:\n  occlusion_margin_px: 0\n  line_index_drop_row_offset_px: 0.2\n", "test");
  EXPECT_EQ(o.match.occlusion_margin_px, 0.0);
  EXPECT_EQ(o.match.line_index.drop_row_offset_px, 0.2);
  EXPECT_EQ(RuntimeOptions{}.match.occlusion_margin_px, 1.0);
  EXPECT_EQ(RuntimeOptions{}.match.line_index.drop_row_offset_px, 0.15);
  EXPECT_THROW(ParseRuntimeOptions("match:\n  occlusion_margin_px: -1\n", "test"), InputError);
  EXPECT_THROW(ParseRuntimeOptions("match:\n  line_index_drop_row_offset_px: 1.5\n", "test"), InputError);
}

}  // namespace
}  // namespace stereorig
