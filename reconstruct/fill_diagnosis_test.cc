// The diagnosis's truth slope: central differences inside a surface,
// one-sided ones at its silhouette (where the old binning took 0 and so
// counted grazing limbs as frontal); the points' error by their distance
// to the silhouette, on maps built by hand.
#include "reconstruct/fill_diagnosis.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace stereorig {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

TEST(FillDiagnosis, TruthSlopeIsTheAnalyticDerivativeInsideASurface) {
  // d(x) = x^2 sampled at x = 2, 3, 4: the central difference of a quadratic
  // is exact, d'(3) = 6. Exact in float (small integers).
  EXPECT_DOUBLE_EQ(TruthSlopePx(4.0f, 9.0f, 16.0f), 6.0);
}

TEST(FillDiagnosis, TruthSlopeAtASilhouetteIsOneSidedNotZero) {
  // A plane d = 50 + 0.6 x seen up to its silhouette at x = 10 (no truth
  // beyond): the slope there is still 0.6, from the side that has truth.
  auto d = [](int x) { return float(50.0 + 0.6 * x); };
  EXPECT_NEAR(TruthSlopePx(d(9), d(10), kNan), 0.6, 1e-5);  // float rounding of ~56
  EXPECT_NEAR(TruthSlopePx(kNan, d(10), d(11)), 0.6, 1e-5);
}

TEST(FillDiagnosis, TruthSlopeWithoutTruthIsZero) {
  EXPECT_EQ(TruthSlopePx(kNan, 9.0f, kNan), 0.0);   // an isolated truth pixel
  EXPECT_EQ(TruthSlopePx(kNan, kNan, 16.0f), 0.0);  // one neighbour, none at the pixel: no difference
}

TEST(FillDiagnosis, TruthSlopeWithoutCentreTruthStillUsesBothNeighbours) {
  // A pixel whose own 2x2 truth straddles a depth step (NaN) between two
  // pixels that have truth: the central difference, as before session 8.
  EXPECT_DOUBLE_EQ(TruthSlopePx(4.0f, kNan, 16.0f), 6.0);
}

// A 40 x 3 map: an object on x = 10 .. 29 (truth 50 px), nothing
// elsewhere. Points carry a made-up error by column: +1 next to the right
// silhouette (x = 29), +0.5 one further in (x = 28), -1 next to the left
// one (x = 10), +0.25 elsewhere. All values are exact in float.
struct SilhouetteMaps {
  cv::Mat disparity{3, 40, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity())};
  cv::Mat truth{3, 40, CV_32FC1, cv::Scalar(kNan)};
  cv::Mat status{3, 40, CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kNotSearched))};
  SilhouetteMaps() {
    for (int x = 10; x <= 29; ++x) SetColumn(x, x == 29 ? 1.0f : x == 28 ? 0.5f : x == 10 ? -1.0f : 0.25f);
  }
  // Column x on the object (truth 50 px) in every row, a point off by e.
  void SetColumn(int x, float e) {
    for (int y = 0; y < 3; ++y) {
      truth.at<float>(y, x) = 50;
      disparity.at<float>(y, x) = 50 + e;
      status.at<uint8_t>(y, x) = uint8_t(PixelStatus::kPoint);
    }
  }
};

TEST(FillDiagnosis, SilhouetteProfileBinsPointsByTheirDistanceToTheObjectsEdge) {
  SilhouetteMaps m;
  // Not points: a lost pixel (status) and one without a disparity.
  m.status.at<uint8_t>(2, 29) = uint8_t(PixelStatus::kLowZncc);
  m.disparity.at<float>(0, 28) = std::numeric_limits<float>::infinity();
  const SilhouetteErrorProfile p = ProfileSilhouetteError(m.disparity, m.truth, m.status);
  EXPECT_EQ(p.right_count[1], 2);  // x = 29, rows 0 and 1
  EXPECT_DOUBLE_EQ(p.right_mean_px[1], 1.0);
  EXPECT_EQ(p.right_count[2], 2);  // x = 28, rows 1 and 2
  EXPECT_DOUBLE_EQ(p.right_mean_px[2], 0.5);
  for (int k = 3; k <= SilhouetteErrorProfile::kMaxDistancePx; ++k) {  // x = 30 - k
    EXPECT_EQ(p.right_count[k], 3) << k;
    EXPECT_DOUBLE_EQ(p.right_mean_px[k], 0.25) << k;
  }
  EXPECT_EQ(p.left_count[1], 3);  // x = 10
  EXPECT_DOUBLE_EQ(p.left_mean_px[1], -1.0);
  EXPECT_EQ(p.left_count[6], 3);  // x = 15
  EXPECT_DOUBLE_EQ(p.left_mean_px[6], 0.25);
  // More than 6 px from both edges (at x = 9 and x = 30): x = 16 .. 23
  // (8 px in 3 rows).
  EXPECT_EQ(p.interior_count, 24);
  EXPECT_DOUBLE_EQ(p.interior_mean_px, 0.25);
  // Points > 1 px off: none (the +1 is not more than 1).
  EXPECT_EQ(p.right_off_1px[1], 0);
  EXPECT_NE(p.Summary().find("right 1: 2 (0): +1.00 2: 2 (0): +0.50"), std::string::npos) << p.Summary();
  EXPECT_NE(p.Summary().find("left 1: 3 (0): -1.00 2: 3 (0): +0.25"), std::string::npos) << p.Summary();
}

TEST(FillDiagnosis, SilhouetteProfileDoesNotTakeTheImagesBorderForAnEdge) {
  SilhouetteMaps m;
  // The object now runs to the image's right border (x = 39): no point has
  // a silhouette on its right any more.
  for (int x = 30; x < 40; ++x) m.SetColumn(x, 0.25f);
  const SilhouetteErrorProfile p = ProfileSilhouetteError(m.disparity, m.truth, m.status);
  for (int k = 1; k <= SilhouetteErrorProfile::kMaxDistancePx; ++k) EXPECT_EQ(p.right_count[k], 0) << k;
  EXPECT_NE(p.Summary().find("right none;"), std::string::npos) << p.Summary();
  // The same at the left border: the object from x = 0 has no silhouette on
  // its left.
  for (int x = 0; x < 10; ++x) m.SetColumn(x, 0.25f);
  const SilhouetteErrorProfile whole = ProfileSilhouetteError(m.disparity, m.truth, m.status);
  EXPECT_EQ(whole.interior_count, 120);  // every point of the 40 x 3 map
  EXPECT_NE(whole.Summary().find("right none; left none;"), std::string::npos) << whole.Summary();
  EXPECT_EQ(p.left_count[1], 3);
  // x = 16 .. 39 (24 px in 3 rows), x = 28 and 29 among them with their
  // +0.5 and +1.
  EXPECT_EQ(p.interior_count, 72);
  EXPECT_DOUBLE_EQ(p.interior_mean_px, (3 * (22 * 0.25 + 0.5 + 1.0)) / 72);
}

TEST(FillDiagnosis, SilhouetteProfileCountsAThinObjectOnBothSides) {
  // 3 px wide (x = 10 .. 12): each point is near both edges, none interior.
  cv::Mat truth(1, 20, CV_32FC1, cv::Scalar(kNan)), disparity(1, 20, CV_32FC1, cv::Scalar(kNan));
  cv::Mat status(1, 20, CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kPoint)));
  for (int x = 10; x <= 12; ++x) truth.at<float>(0, x) = 40, disparity.at<float>(0, x) = float(40 + (x - 10));
  const SilhouetteErrorProfile p = ProfileSilhouetteError(disparity, truth, status);
  EXPECT_EQ(p.right_count[1], 1);  // x = 12, error +2
  EXPECT_DOUBLE_EQ(p.right_mean_px[1], 2.0);
  EXPECT_EQ(p.right_count[3], 1);            // x = 10, error 0
  EXPECT_EQ(p.left_count[1], 1);             // x = 10
  EXPECT_DOUBLE_EQ(p.left_mean_px[3], 2.0);  // x = 12
  // x = 11 is 2 px from both, error +1.
  EXPECT_EQ(p.right_count[2], 1);
  EXPECT_EQ(p.left_count[2], 1);
  EXPECT_DOUBLE_EQ(p.right_mean_px[2], 1.0);
  EXPECT_DOUBLE_EQ(p.left_mean_px[2], 1.0);
  EXPECT_EQ(p.right_off_1px[1], 1);  // x = 12: +2
  EXPECT_EQ(p.left_off_1px[3], 1);
  EXPECT_EQ(p.interior_count, 0);
}

// Where the truth ends because the left view's data does (the rectified
// pixel's source is off the sensor), that is no silhouette either.
TEST(FillDiagnosis, SilhouetteProfileDoesNotTakeTheLeftViewsEdgeForAnEdge) {
  SilhouetteMaps m;
  cv::Mat left_valid(3, 40, CV_8UC1, cv::Scalar(255));
  left_valid.colRange(30, 40).setTo(0);  // no view right of the object
  const SilhouetteErrorProfile p = ProfileSilhouetteError(m.disparity, m.truth, m.status, left_valid);
  for (int k = 1; k <= SilhouetteErrorProfile::kMaxDistancePx; ++k) EXPECT_EQ(p.right_count[k], 0) << k;
  EXPECT_EQ(p.left_count[1], 3);        // the left silhouette still is one
  EXPECT_EQ(p.interior_count, 3 * 14);  // x = 16 .. 29
}

// Every status a target pixel can end in has its own colour in the status
// image, so the image tells them apart (low_texture and
// seen_through_surface were both purple before), except off_plane_coarse,
// drawn with off_plane on purpose; none is the white of the statuses no
// target holds.
TEST(FillDiagnosis, EachLossHasItsOwnColour) {
  std::map<std::array<uint8_t, 3>, std::string> seen;
  for (int k = 0; k < int(PixelStatus::kNumStatus); ++k) {
    const PixelStatus status = PixelStatus(k);
    if (status == PixelStatus::kOffPlaneCoarse) continue;
    const cv::Vec3b c = DiagnosisColour(status);
    const std::array<uint8_t, 3> bgr{c[0], c[1], c[2]};
    if (bgr == std::array<uint8_t, 3>{255, 255, 255}) continue;  // not a target's status
    const auto [it, inserted] = seen.emplace(bgr, PixelStatusName(status));
    EXPECT_TRUE(inserted) << PixelStatusName(status) << " has " << it->second << "'s colour";
  }
  EXPECT_EQ(DiagnosisColour(PixelStatus::kOffPlaneCoarse), DiagnosisColour(PixelStatus::kOffPlane));
  // The statuses the guide lists with a colour of their own: 16, point included.
  EXPECT_EQ(seen.size(), 16u);
}

}  // namespace
}  // namespace stereorig
