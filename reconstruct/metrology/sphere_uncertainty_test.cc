// The fitted diameter's scatter over a sphere's cap, measured on many noisy
// synthetic caps, against what the fit's covariance predicts for one cap
// (SphereUncertainty). The table this prints is the basis of verify's rule
// for an undetermined P_S (docs/verify-and-check.md).
#include "reconstruct/metrology/sphere_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <utility>

#include "reconstruct/metrology/synthetic_shapes.h"

namespace stereorig {
namespace {

// Fits `trials` caps drawn by `draw` (a sphere of radius r_mm about
// `centre`) and returns the fitted diameters' scatter (standard deviation)
// beside the means of what SphereUncertainty said of each.
struct CapTrials {
  double scatter_mm = 0, predicted_mm = 0, cap_deg = 0, inflation = 0;
};
CapTrials FitCaps(const std::function<std::vector<Eigen::Vector3d>()>& draw, const Eigen::Vector3d& centre, double r_mm,
                  int trials) {
  double sum = 0, sum2 = 0;
  CapTrials out;
  for (int t = 0; t < trials; ++t) {
    const std::vector<Eigen::Vector3d> pts = draw();
    std::vector<int> all(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) all[i] = static_cast<int>(i);
    const SphereFit fit = RefineSphere(pts, all, centre, r_mm, 50);
    EXPECT_TRUE(fit.ok) << fit.message;
    if (!fit.ok) return out;
    const SphereFitUncertainty u = SphereUncertainty(pts, fit);
    sum += 2 * fit.radius_mm;
    sum2 += 4 * fit.radius_mm * fit.radius_mm;
    out.predicted_mm += u.diameter_std_mm / trials;
    out.cap_deg += u.cap_half_angle_deg / trials;
    out.inflation += u.noise_variance_inflation / trials;
  }
  const double mean = sum / trials;
  out.scatter_mm = std::sqrt((sum2 - trials * mean * mean) / (trials - 1));
  return out;
}

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
    const CapTrials caps = FitCaps(
        [&] {
          return testing::NoisySurfaceSamples(testing::SphereCapSurface(centre, axis, r_mm, half_angle_deg), count,
                                              noise_mm, &rng);
        },
        centre, r_mm, trials);
    const double scatter = caps.scatter_mm, predicted = caps.predicted_mm, cap_deg = caps.cap_deg;
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

// With noise correlated between neighbouring points the fit's covariance
// counted each point as independent and predicted the diameter's scatter
// 2.3-6x too small here (7-8x on the demo's reconstructed sphere, whose caps
// of 18-20 degrees so read P_S -1.8 mm "determined" to +-0.12 mm, FAIL, on
// a rig whose whole sphere reads -0.02 mm). The inflation measured from the
// residuals (NoiseVarianceInflation) brings the prediction to the scatter.
// Truth: 38.1 mm sphere, 3000 points per cap, a field of 0.05 mm on a 1 mm
// lattice (correlated up to 2 mm, as the demo's noise) plus 0.01 mm
// independent noise; T = 200 caps per row, the scatter's relative standard
// error 1 / sqrt(2 (T - 1)) = 5%. Measured ratios 1.10, 1.28, 1.29 (the
// demo's caps: 0.9-1.24): a small cap's residuals lose the part of the
// field its sphere absorbs, so the estimate stays somewhat under the
// scatter. Bounds [0.8, 1.4], 4 and 8 standard errors from 1.
TEST(SphereUncertainty, PredictsTheDiameterScatterOfCapsWhoseNoiseNeighbouringPointsShare) {
  const double r_mm = 19.05;
  const int count = 3000, trials = 200;
  const Eigen::Vector3d centre(3, -2, 150), axis(0.1, 0.2, -1);
  for (double half_angle_deg : {60.0, 30.0, 20.0}) {
    std::mt19937 rng(static_cast<unsigned>(100 + half_angle_deg));
    const CapTrials caps = FitCaps(
        [&] {
          return testing::CorrelatedNoiseSamples(testing::SphereCapSurface(centre, axis, r_mm, half_angle_deg), count,
                                                 0.05, 1.0, 0.01, &rng);
        },
        centre, r_mm, trials);
    const double scatter = caps.scatter_mm, predicted = caps.predicted_mm;
    std::printf("%4.0f deg: scatter of D %.4f mm, predicted %.4f mm (ratio %.3f), variance inflation %.1f\n",
                half_angle_deg, scatter, predicted, scatter / predicted, caps.inflation);
    EXPECT_GT(scatter / predicted, 0.8) << half_angle_deg;
    EXPECT_LT(scatter / predicted, 1.4) << half_angle_deg;
  }
}

// Independent noise reads no inflation: the statistic less twice its
// standard error is at most 1 (clamped to it) but in ~2% of clouds. Truth:
// 30-degree caps, 0.05 mm independent noise; 100 clouds of 2000 points, and
// 5 of 20 000 (65 points per mm^2, 0.12 mm apart: as close as their noise,
// where neighbours taken by the points' own places, not their places on the
// sphere, read 1.6 for 200 000 points over a whole sphere: a pair of
// residuals of one sign lies closer than one of opposite signs).
TEST(SphereUncertainty, IndependentNoiseIsNotInflated) {
  std::mt19937 rng(7);
  for (const auto& [count, clouds] : {std::pair{2000, 100}, std::pair{20000, 5}}) {
    int inflated = 0;
    double largest = 1;
    for (int t = 0; t < clouds; ++t) {
      const std::vector<Eigen::Vector3d> pts = testing::NoisySurfaceSamples(
          testing::SphereCapSurface({0, 0, 150}, {0, 0, -1}, 19.05, 30), count, 0.05, &rng);
      std::vector<int> all(pts.size());
      for (int i = 0; i < count; ++i) all[i] = i;
      const SphereFit fit = RefineSphere(pts, all, {0, 0, 150}, 19.05, 50);
      ASSERT_TRUE(fit.ok) << fit.message;
      const double inflation = SphereUncertainty(pts, fit).noise_variance_inflation;
      inflated += inflation > 1;
      largest = std::max(largest, inflation);
    }
    EXPECT_LE(inflated, 0.08 * clouds + 1) << count;
    EXPECT_LT(largest, 1.3) << count;
  }
}

// A pattern on the surface is not noise. A patch of a ball lying off it (a
// grid period off, 5 mm across the ball's 12.7 mm radius, 0.3 or 1 mm) is
// correlated over its whole size; taken as noise neighbouring points share
// it multiplied the variances by ~110 (u x10), whatever its height, and a
// ball bar failing SD by 0.04 mm read NOT JUDGED (the reviewer's clouds).
// Truth: 15 000 points on an 80-degree cap with 0.03 mm independent noise,
// alone or with the correlated noise of the test above (field 0.05 mm, 1 mm
// cells), then the same cloud with the patch. What u may hold: the noise's
// own u (the clean cloud's, inflated) and the patch's residuals as the
// plain fit counts them (u without the inflation): u^2 ~ u_clean^2 +
// u_white^2. Measured 1.4-2.1 times that (the line through the far
// products, extrapolated over the near band, leaves part of the patch's
// profile there); the defect read ~10 times. Bounds: at most 2.5 times,
// and the noise's inflation is not taken out with the pattern (u at least
// the clean cloud's / 1.3).
TEST(SphereUncertainty, APatchOffTheSurfaceIsAPatternNotNoise) {
  const double r_mm = 12.7;
  const Eigen::Vector3d centre(40, 0, 200), axis(0, 0, -1);
  const Eigen::Vector3d patch_direction = Eigen::Vector3d(std::sin(0.61), 0, -std::cos(0.61));
  for (const double field_mm : {0.0, 0.05}) {
    for (const double patch_mm : {0.3, 1.0}) {
      std::mt19937 rng(11);
      std::vector<Eigen::Vector3d> pts =
          field_mm > 0
              ? testing::CorrelatedNoiseSamples(testing::SphereCapSurface(centre, axis, r_mm, 80), 15000, field_mm, 1.0,
                                                0.03, &rng)
              : testing::NoisySurfaceSamples(testing::SphereCapSurface(centre, axis, r_mm, 80), 15000, 0.03, &rng);
      std::vector<int> all(pts.size());
      for (size_t i = 0; i < pts.size(); ++i) all[i] = static_cast<int>(i);
      const SphereFit clean = RefineSphere(pts, all, centre, r_mm, 50);
      ASSERT_TRUE(clean.ok) << clean.message;
      const SphereFitUncertainty u_clean = SphereUncertainty(pts, clean);
      const double noise_inflation = u_clean.noise_variance_inflation;
      int on_patch = 0;
      for (Eigen::Vector3d& p : pts) {
        const Eigen::Vector3d n = (p - centre).normalized();
        if (r_mm * (n - patch_direction).norm() < 5.0) p += patch_mm * n, ++on_patch;
      }
      const SphereFit fit = RefineSphere(pts, all, centre, r_mm, 50);
      ASSERT_TRUE(fit.ok) << fit.message;
      const SphereFitUncertainty u = SphereUncertainty(pts, fit);
      const double inflation = u.noise_variance_inflation;
      const double u_white = u.diameter_std_mm / std::sqrt(inflation);
      const double expected = std::hypot(u_clean.diameter_std_mm, u_white);
      std::printf(
          "field %.2f mm, patch %.1f mm on %d points: inflation %.2f (the noise alone %.2f); u %.5f mm, "
          "%.2f x sqrt(u_clean^2 + u_white^2)\n",
          field_mm, patch_mm, on_patch, inflation, noise_inflation, u.diameter_std_mm, u.diameter_std_mm / expected);
      EXPECT_GT(on_patch, 1000);
      EXPECT_LT(u.diameter_std_mm, 2.5 * expected) << field_mm << " " << patch_mm;
      EXPECT_GT(u.diameter_std_mm, u_clean.diameter_std_mm / 1.3) << field_mm << " " << patch_mm;
    }
  }
}

}  // namespace
}  // namespace stereorig
