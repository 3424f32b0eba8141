// ResidualField against analytic fields: a smooth residual on a
// hemisphere, with Gaussian noise and gross outliers, must be recovered to
// within a tolerance set by the noise; residuals that are noise only (an
// exact model) must give no field at all; far from the data the field
// returns to the model.
#include "reconstruct/residual_field.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
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

// The held-out residuals of the length choice (residual_field.h) from the
// closed form against refitting without each block: the same numbers up to
// rounding (1e-9 relative), on random cells with random weights.
TEST(ResidualField, HeldOutBlockErrorIsTheRefitWithoutEachBlock) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-20, 20), w(0.5, 2);
  const int n = 120;
  Eigen::Matrix3Xd x(3, n);
  Eigen::VectorXd y(n), weights(n);
  for (int i = 0; i < n; ++i) {
    x.col(i) = Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng));
    y(i) = TrueField(x.col(i)) + 0.05 * u(rng) / 20;
    weights(i) = w(rng);
  }
  const double length = 9, ratio = 0.05, block = 15;
  Eigen::MatrixXd c(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) c(i, j) = std::exp(-(x.col(i) - x.col(j)).squaredNorm() / (2 * length * length));
  const double closed_form = internal::BlockCrossValidationError(c, ratio, weights, y, x, block);
  // Refit: for each block B, predict y_B from the rest, A_B,rest A_rest^-1 y_rest.
  std::map<std::array<int, 3>, std::vector<int>> blocks;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3i b = (x.col(i) / block).array().floor().cast<int>();
    blocks[{b.x(), b.y(), b.z()}].push_back(i);
  }
  ASSERT_GT(blocks.size(), 10u);
  Eigen::MatrixXd a = c;
  a.diagonal() += ratio * weights.cwiseInverse();
  double refit = 0;
  for (const auto& [key, in_block] : blocks) {
    std::vector<int> rest;
    for (int i = 0; i < n; ++i)
      if (std::find(in_block.begin(), in_block.end(), i) == in_block.end()) rest.push_back(i);
    Eigen::MatrixXd a_rest(rest.size(), rest.size()), a_block_rest(in_block.size(), rest.size());
    Eigen::VectorXd y_rest(rest.size());
    for (size_t r = 0; r < rest.size(); ++r) {
      y_rest(r) = y(rest[r]);
      for (size_t q = 0; q < rest.size(); ++q) a_rest(r, q) = a(rest[r], rest[q]);
      for (size_t b = 0; b < in_block.size(); ++b) a_block_rest(b, r) = a(in_block[b], rest[r]);
    }
    const Eigen::VectorXd predicted = a_block_rest * a_rest.llt().solve(y_rest);
    for (size_t b = 0; b < in_block.size(); ++b)
      refit += weights(in_block[b]) * std::pow(y(in_block[b]) - predicted(b), 2);
  }
  EXPECT_NEAR(closed_form, refit, 1e-9 * refit);
  EXPECT_GT(refit, 0);
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
