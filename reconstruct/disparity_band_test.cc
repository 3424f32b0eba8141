#include "reconstruct/disparity_band.h"

#include <gtest/gtest.h>

#include <random>

namespace stereorig {
namespace {

// n samples uniform in [lo, hi).
void AddUniform(std::vector<float>* v, std::mt19937& rng, int n, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  for (int i = 0; i < n; ++i) v->push_back(u(rng));
}

TEST(DisparityBand, DropsSmallIsolatedClustersOfMismatches) {
  // The shape measured on the simulator's sphere: the object over 40 px, and
  // two small clusters (4 % and 3 %) about 100 px either side.
  std::mt19937 rng(1);
  std::vector<float> v;
  AddUniform(&v, rng, 9000, 0, 40);
  AddUniform(&v, rng, 400, 100, 120);
  AddUniform(&v, rng, 300, -100, -90);
  const auto band = OccupiedDisparityBand(v, 6);
  ASSERT_TRUE(band.has_value());
  // The object's extent plus the margin, to within one 4 px bin.
  EXPECT_GE(band->min_px, -6 - 4);
  EXPECT_LE(band->min_px, -6);
  EXPECT_GE(band->max_px, 40 + 6);
  EXPECT_LE(band->max_px, 40 + 6 + 4);
}

TEST(DisparityBand, KeepsEverySubstantialSurface) {
  // Two real surfaces (70 % and 30 %) 60 px apart with nothing between: both
  // are kept, so the band spans the gap.
  std::mt19937 rng(2);
  std::vector<float> v;
  AddUniform(&v, rng, 7000, 10, 30);
  AddUniform(&v, rng, 3000, 90, 100);
  const auto band = OccupiedDisparityBand(v, 6);
  ASSERT_TRUE(band.has_value());
  EXPECT_LE(band->min_px, 10 - 6);
  EXPECT_GE(band->max_px, 100 + 6);
}

TEST(DisparityBand, BridgesSparseStretchesInsideOneSurface) {
  // A steep flank: a dense part, then 20 px with few matches, then more
  // surface (8 %, below the cluster share on its own): one cluster.
  std::mt19937 rng(3);
  std::vector<float> v;
  AddUniform(&v, rng, 9000, 0, 30);
  AddUniform(&v, rng, 5, 30, 50);
  AddUniform(&v, rng, 800, 50, 60);
  const auto band = OccupiedDisparityBand(v, 0);
  ASSERT_TRUE(band.has_value());
  EXPECT_GE(band->max_px, 60);
}

TEST(DisparityBand, TooFewMatchesGiveNoBand) {
  std::mt19937 rng(4);
  std::vector<float> v;
  AddUniform(&v, rng, kMinBandMatches - 1, 0, 40);
  EXPECT_FALSE(OccupiedDisparityBand(v, 6).has_value());
}

}  // namespace
}  // namespace stereorig
