// ProximityGrid against brute force: every answer must equal the exhaustive
// one, on clustered points with far outliers and queries inside, on the
// border of and outside the points' box, at radii below, at and above the
// cell size.
#include "reconstruct/proximity_grid.h"

#include <gtest/gtest.h>

#include <random>

namespace stereorig {
namespace {

bool BruteAnyWithin(const std::vector<Eigen::Vector3f>& pts, const Eigen::Vector3d& q, double r) {
  for (const auto& p : pts)
    if ((p - q.cast<float>()).squaredNorm() <= float(r * r)) return true;
  return false;
}

TEST(ProximityGrid, AgreesWithBruteForce) {
  std::mt19937 rng(3);
  std::normal_distribution<float> cluster(0, 8);
  std::normal_distribution<double> around(0, 14);  // queries: inside, at the edge of and beyond the cluster
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 3000; ++i) pts.emplace_back(cluster(rng), cluster(rng), 200 + cluster(rng));
  pts.emplace_back(500, -300, 900);  // a far outlier stretches the box
  for (double cell : {0.7, 2.0, 5.0}) {
    const ProximityGrid grid(pts, cell);
    int hits = 0, misses = 0;
    for (int k = 0; k < 4000; ++k) {
      const Eigen::Vector3d q(around(rng), around(rng), 200 + around(rng));
      for (double r : {0.3, cell, 2.5 * cell}) {
        const bool expected = BruteAnyWithin(pts, q, r);
        ASSERT_EQ(grid.AnyWithin(q, r), expected) << "cell " << cell << " r " << r << " q " << q.transpose();
        (expected ? hits : misses) += 1;
      }
    }
    // Both answers occur often enough for the comparison to mean something.
    EXPECT_GT(hits, 1000);
    EXPECT_GT(misses, 1000);
    // Far outside the box, and exactly at a point.
    EXPECT_FALSE(grid.AnyWithin(Eigen::Vector3d(-1e4, 1e4, 0), 1.0));
    EXPECT_TRUE(grid.AnyWithin(pts[17].cast<double>(), 0.0));
    EXPECT_TRUE(grid.AnyWithin(Eigen::Vector3d(500, -300, 900.5), 0.6));
  }
  EXPECT_FALSE(ProximityGrid({}, 1.0).AnyWithin(Eigen::Vector3d::Zero(), 10));
}

}  // namespace
}  // namespace stereorig
