// The fitted diameter's scatter over a sphere's cap, measured on many noisy
// synthetic caps, against what the fit's covariance predicts for one cap
// (SphereUncertainty). The table this prints is the basis of verify's rule
// for an undetermined P_S (docs/verify-and-check.md).
#include "reconstruct/metrology/sphere_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "reconstruct/metrology/synthetic_shapes.h"

namespace stereorig {
namespace {

TEST(SphereUncertainty, PredictsTheDiameterScatterOfCapsFromHemisphereToTenDegrees) {
  // The runtime's noise (0.05 mm along the normal, docs/reconstruct.md), the
  // demo's 38.1 mm sphere, 2000 points per cap. The scatter's standard
  // deviation over T = 300 caps has a relative standard error of
  // 1 / sqrt(2 (T - 1)) = 4.1%: a ratio of scatter to prediction outside
  // [0.8, 1.25] is > 5 of those from 1.
  const double r_mm = 19.05, noise_mm = 0.05;
  const int count = 2000, trials = 300;
  const Eigen::Vector3d centre(3, -2, 150), axis(0.1, 0.2, -1);
  std::printf("%9s %8s %14s %14s %7s %16s\n", "half_deg", "cap_deg", "scatter_D_mm", "predicted_mm", "ratio",
              "at_16_pts_mm2");
  for (double half_angle_deg : {90.0, 60.0, 45.0, 30.0, 20.0, 15.0, 10.0}) {
    std::mt19937 rng(static_cast<unsigned>(half_angle_deg));
    double sum = 0, sum2 = 0, predicted_sum = 0, cap_sum_deg = 0;
    for (int t = 0; t < trials; ++t) {
      const std::vector<Eigen::Vector3d> pts = testing::NoisySurfaceSamples(
          testing::SphereCapSurface(centre, axis, r_mm, half_angle_deg), count, noise_mm, &rng);
      std::vector<int> all(pts.size());
      for (int i = 0; i < count; ++i) all[i] = i;
      const SphereFit fit = RefineSphere(pts, all, centre, r_mm, 50);
      ASSERT_TRUE(fit.ok) << fit.message;
      const SphereFitUncertainty u = SphereUncertainty(pts, fit);
      sum += 2 * fit.radius_mm;
      sum2 += 4 * fit.radius_mm * fit.radius_mm;
      predicted_sum += u.diameter_std_mm;
      cap_sum_deg += u.cap_half_angle_deg;
    }
    const double mean = sum / trials, scatter = std::sqrt((sum2 - trials * mean * mean) / (trials - 1));
    const double predicted = predicted_sum / trials, cap_deg = cap_sum_deg / trials;
    // The same cap at the demo sphere's density (~16 points per mm^2; 50 000
    // points on two 70-degree caps): the uncertainty goes as 1 / sqrt(N).
    const double area_mm2 = 2 * M_PI * r_mm * r_mm * (1 - std::cos(half_angle_deg * M_PI / 180));
    std::printf("%9.0f %8.1f %14.4f %14.4f %7.3f %16.4f\n", half_angle_deg, cap_deg, scatter, predicted,
                scatter / predicted, predicted * std::sqrt(count / (16 * area_mm2)));
    EXPECT_GT(scatter / predicted, 0.8) << half_angle_deg;
    EXPECT_LT(scatter / predicted, 1.25) << half_angle_deg;
    // 99% of a cap uniform in area lie within acos(1 - 0.99 (1 - cos theta)).
    // The points' mean direction, the cone's axis, tilts by the sampling (1
    // sigma per axis sqrt(<sin^2 t> / 2N) / <cos t>: 1.5 deg for a hemisphere
    // of 2000 points, 0.2 deg at 20 deg), which widens the cone by a fraction
    // of that (+0.6 deg measured on the hemisphere).
    const double expected_cap_deg = std::acos(1 - 0.99 * (1 - std::cos(half_angle_deg * M_PI / 180))) * 180 / M_PI;
    EXPECT_NEAR(cap_deg, expected_cap_deg, 1.0) << half_angle_deg;
  }
}

}  // namespace
}  // namespace stereorig
