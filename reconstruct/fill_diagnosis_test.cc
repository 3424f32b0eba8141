// The diagnosis's truth slope: central differences inside a surface,
// one-sided ones at its silhouette (where the old binning took 0 and so
// counted grazing limbs as frontal).
#include "reconstruct/fill_diagnosis.h"

#include <gtest/gtest.h>

#include <limits>

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

}  // namespace
}  // namespace stereorig
