// ResidualField against analytic fields: a smooth residual on a
// hemisphere, with Gaussian noise and gross outliers, must be recovered to
// within a tolerance set by the noise; residuals that are noise only (an
// exact model) must give no field at all; far from the data the field
// returns to the model.
#include "reconstruct/residual_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace stereorig {
namespace {

// A smooth field (features ~10 mm, amplitude ~1 mm), like a tuber's bumps.
double TrueField(const Eigen::Vector3d& p) { return 0.8 * std::sin(p.x() / 9) * std::cos(p.y() / 11) + 0.3; }

// n points uniform on the hemisphere z < 0 of radius 30 mm.
std::vector<Eigen::Vector3d> Hemisphere(int n, std::mt19937* rng) {
  std::normal_distribution<double> g(0, 1);
  std::vector<Eigen::Vector3d> pts;
  while (int(pts.size()) < n) {
    Eigen::Vector3d v(g(*rng), g(*rng), g(*rng));
    if (v.z() > 0) v.z() = -v.z();
    pts.push_back(30 * v.normalized());
  }
  return pts;
}

TEST(ResidualField, RecoversASmoothResidualToTheNoise) {
  constexpr double kNoiseMm = 0.05;  // like a module's point noise
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, kNoiseMm);
  std::uniform_real_distribution<double> wild(-10, 10);
  const std::vector<Eigen::Vector3d> pts = Hemisphere(20000, &rng);
  std::vector<double> r;
  for (size_t i = 0; i < pts.size(); ++i)
    r.push_back(i % 50 == 0 ? wild(rng) : TrueField(pts[i]) + noise(rng));  // 2% gross outliers
  const ResidualField field = ResidualField::Fit(pts, r, ResidualFieldOptions{});
  ASSERT_TRUE(field.active()) << field.description();
  std::printf("%s\n", field.description().c_str());
  // Held-out points on the seen hemisphere, away from its rim.
  double sum2 = 0, worst = 0;
  int n = 0;
  for (const Eigen::Vector3d& p : Hemisphere(2000, &rng)) {
    if (p.z() > -8) continue;
    const double e = field.Predict(p) - TrueField(p);
    sum2 += e * e;
    worst = std::max(worst, std::abs(e));
    ++n;
  }
  const double rms = std::sqrt(sum2 / n);
  std::printf("error against the true field: rms %.4f mm, worst %.4f mm over %d points\n", rms, worst, n);
  // ~1000 cell means of ~20 points each fitted, each field value averaged
  // over the cells within a length scale: the noise alone leaves well under
  // 0.05 / sqrt(20) = 0.011 mm; the tolerance allows the kernel's smoothing
  // of a 1 mm field several times that: rms below the noise sigma, worst
  // below 3 sigma.
  EXPECT_LT(rms, kNoiseMm);
  EXPECT_LT(worst, 3 * kNoiseMm);
  // The noise it estimated is that of a cell mean: the injected noise
  // averaged over the ~20 points of a cell (0.011 mm), within the ratio
  // grid's factor-of-3 steps, and below the noise of one point.
  const double cell_noise_mm = kNoiseMm / std::sqrt(19600.0 / 1000);
  EXPECT_GT(field.noise_sd_mm(), 0.5 * cell_noise_mm);
  EXPECT_LT(field.noise_sd_mm(), kNoiseMm);
  // Far from every data point (5 length scales), the field is the model's 0.
  EXPECT_LT(std::abs(field.Predict(Eigen::Vector3d(0, 0, 30 + 5 * field.length_mm()))), 1e-3);
}

TEST(ResidualField, AGivenLengthScaleIsUsed) {
  std::mt19937 rng(8);
  const std::vector<Eigen::Vector3d> pts = Hemisphere(3000, &rng);
  std::vector<double> r;
  for (const auto& p : pts) r.push_back(TrueField(p));
  ResidualFieldOptions o;
  o.length_mm = 14;
  const ResidualField field = ResidualField::Fit(pts, r, o);
  ASSERT_TRUE(field.active());
  EXPECT_EQ(field.length_mm(), 14);
}

TEST(ResidualField, IsOffWhenTheModelIsExact) {
  // Residuals that are noise only (0.05 mm, plus outliers): rms < 0.1 mm.
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0, 0.05);
  const std::vector<Eigen::Vector3d> pts = Hemisphere(20000, &rng);
  std::vector<double> r;
  for (size_t i = 0; i < pts.size(); ++i) r.push_back(i % 40 == 0 ? 5.0 : noise(rng));
  const ResidualField field = ResidualField::Fit(pts, r, ResidualFieldOptions{});
  EXPECT_FALSE(field.active()) << field.description();
  EXPECT_NE(field.description().find("off"), std::string::npos);
  EXPECT_EQ(field.Predict(pts[3]), 0.0);
  EXPECT_NEAR(field.residual_rms_mm(), 0.05, 0.005);  // the outliers were cut
  EXPECT_EQ(ResidualField().Predict(pts[0]), 0.0);
}

}  // namespace
}  // namespace stereorig
