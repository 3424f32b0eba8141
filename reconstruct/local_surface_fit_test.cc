// The local quadric fit of the disparities (local_surface_fit.h) against
// analytic disparity fields: a quadric surface is kept exactly, independent
// noise falls by the factor least squares predicts, and a depth step and a
// silhouette are left alone.
#include "reconstruct/local_surface_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

namespace stereorig {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A curved surface's disparity field (px): a quadric in the pixel
// coordinates, as a sphere's is near its centre.
double Quadric(int x, int y) {
  const double u = x - 100.0, v = y - 60.0;
  return 40 + 0.05 * u - 0.02 * v + 4e-4 * u * u + 2e-4 * u * v + 6e-4 * v * v;
}

TEST(LocalSurfaceFit, KeepsAQuadricAndCutsIndependentNoiseAsPredicted) {
  const double sigma_px = 0.3;  // about the speckle scatter of the simulator's disparities
  cv::Mat d(120, 200, CV_32F), truth(120, 200, CV_32F);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, sigma_px);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) {
      truth.at<float>(y, x) = float(Quadric(x, y));
      d.at<float>(y, x) = float(Quadric(x, y) + noise(rng));
    }
  cv::Mat clean = truth.clone();
  SurfaceFitOptions options;        // 21 x 11
  options.reference_misfit_px = 0;  // that window alone (the noise is above the reference: it would grow)
  // At least every pixel whose window only one image edge cuts (at most
  // half a window: up to 3.2x / 4.1x a full window's variance, within
  // max_variance_growth): all but the 5 x 10 pixels nearest each corner.
  EXPECT_GE(FitLocalSurface(cv::Rect(0, 0, d.cols, d.rows), options, 2, &clean), d.rows * d.cols - 4 * 5 * 10);
  double worst = 0;
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x)
      worst = std::max(worst, double(std::abs(clean.at<float>(y, x) - truth.at<float>(y, x))));
  // The sums are float: ~1e-7 relative of values within +-10 px of their mean.
  EXPECT_LT(worst, 2e-4) << "a quadric is reproduced exactly (no curvature bias)";

  FitLocalSurface(cv::Rect(0, 0, d.cols, d.rows), options, 2, &d);
  // Interior pixels (full windows): least squares predicts sigma *
  // sqrt((A^T A)^-1 [0, 0]) = 0.3 * sqrt(0.0153) = 0.037 px for independent
  // errors. The rms over N ~ 17000 pixels scatters by ~1/sqrt(2 N_eff)
  // relative, N_eff ~ N / 231 (neighbouring fits share their data): 8%; 3
  // of those.
  double sum2 = 0;
  int n = 0;
  for (int y = 6; y < d.rows - 6; ++y)
    for (int x = 11; x < d.cols - 11; ++x, ++n) sum2 += std::pow(d.at<float>(y, x) - truth.at<float>(y, x), 2);
  const double rms = std::sqrt(sum2 / n), predicted = sigma_px * std::sqrt(0.0153);
  EXPECT_NEAR(rms, predicted, 0.24 * predicted) << n << " pixels";
  std::printf("noise %.2f px -> %.4f px rms after the fit (predicted %.4f)\n", sigma_px, rms, predicted);
}

TEST(LocalSurfaceFit, LeavesDepthStepsAloneAndFitsUpToSilhouettes) {
  // Two planes 5 px of disparity apart (a depth edge) at x = 100, and no
  // data right of x = 160 (a silhouette); independent noise of 0.3 px.
  const double sigma_px = 0.3;
  cv::Mat d(120, 200, CV_32F, cv::Scalar(kInf)), truth(120, 200, CV_32F, cv::Scalar(kInf));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0, sigma_px);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < 160; ++x) {
      truth.at<float>(y, x) = float((x < 100 ? 45.0 : 40.0) + 0.01 * x);
      d.at<float>(y, x) = float(truth.at<float>(y, x) + noise(rng));
    }
  const cv::Mat raw = d.clone();
  FitLocalSurface(cv::Rect(0, 0, d.cols, d.rows), SurfaceFitOptions{}, 2, &d);
  int unchanged_at_edge = 0, edge_pixels = 0, far_off = 0, changed_at_silhouette = 0, silhouette_pixels = 0;
  double silhouette_raw2 = 0, silhouette_fit2 = 0;
  for (int y = 6; y < d.rows - 6; ++y)
    for (int x = 0; x < d.cols; ++x) {
      const float v = d.at<float>(y, x);
      if (x >= 160) {
        EXPECT_FALSE(std::isfinite(v)) << "no point is made where there was none";
        continue;
      }
      // A fit across the step would pull the pixels next to it by up to
      // half the step (2.5 px); untouched pixels are off by the noise, 4.5
      // sigma at most here (1.4 px over 19000 pixels has p ~ 0.1).
      if (std::abs(v - truth.at<float>(y, x)) > 4.5 * sigma_px) ++far_off;
      if (std::abs(x - 100) <= 2) ++edge_pixels, unchanged_at_edge += v == raw.at<float>(y, x);
      if (x >= 158) {
        ++silhouette_pixels, changed_at_silhouette += v != raw.at<float>(y, x);
        silhouette_raw2 += std::pow(raw.at<float>(y, x) - truth.at<float>(y, x), 2);
        silhouette_fit2 += std::pow(v - truth.at<float>(y, x), 2);
      }
    }
  EXPECT_EQ(far_off, 0);
  EXPECT_EQ(unchanged_at_edge, edge_pixels) << "the quadric misfits a window across a step: the pixel keeps its value";
  // Within 1 px of a silhouette the window is cut in half: its centre's
  // predicted variance is 2.3-4.1x a full window's, under
  // max_variance_growth, so the pixel takes the fit, whose scatter is
  // 0.3 * sqrt(4.1 * 0.0153) = 0.075 px at most: a quarter of the raw
  // 0.3 px. Over 216 pixels in ~10 independent windows along the edge the
  // rms scatters by ~1/sqrt(2 * 10) = 22 % relative; 0.5x the raw rms (0.15
  // px) is 2x the worst pixel's prediction, > 4 of those above it.
  EXPECT_EQ(changed_at_silhouette, silhouette_pixels) << "a half window's fit is better than the pixel's own value";
  EXPECT_LT(std::sqrt(silhouette_fit2 / silhouette_pixels), 0.5 * std::sqrt(silhouette_raw2 / silhouette_pixels));
}

// Windows with holes (each has its own 6x6 system) against a plain least
// squares fit written here: the quadric fitted to the window's valid pixels
// by Eigen's QR, evaluated at the centre. 300 rows: the fit builds its
// moment images in bands of 128 output rows (local_surface_fit.cc,
// kBandRows), each band's filters reading the rows around it, so windows
// across the band edges at rows 128 and 256 are compared too.
TEST(LocalSurfaceFit, WindowsWithHolesEqualAPlainLeastSquaresFit) {
  const double sigma_px = 0.3;
  cv::Mat d(300, 120, CV_32F, cv::Scalar(kInf));
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0, sigma_px);
  std::bernoulli_distribution hole(0.3);  // ~30 % of the pixels missing, as rejections scatter on a capture
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x)
      if (!hole(rng)) d.at<float>(y, x) = float(Quadric(x, y) + noise(rng));
  const cv::Mat raw = d.clone();
  SurfaceFitOptions o;
  o.reference_misfit_px = 0;  // one window size, the one compared below
  FitLocalSurface(cv::Rect(0, 0, d.cols, d.rows), o, 2, &d);
  const int hw = o.half_width_px, hh = o.half_height_px;
  // The plain fit's predicted variance of the centre for a full window, the
  // reference of max_variance_growth.
  auto design = [&](int x, int y, bool full, Eigen::MatrixXd* a, Eigen::VectorXd* b) {
    std::vector<std::array<double, 7>> rows;
    for (int v = -hh; v <= hh; ++v)
      for (int u = -hw; u <= hw; ++u) {
        const float value = raw.at<float>(y + v, x + u);
        if (!full && !std::isfinite(value)) continue;
        const double su = double(u) / hw, sv = double(v) / hh;
        rows.push_back({1, su, sv, su * su, su * sv, sv * sv, full ? 0.0 : double(value)});
      }
    a->resize(Eigen::Index(rows.size()), 6), b->resize(Eigen::Index(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) {
      for (int k = 0; k < 6; ++k) (*a)(Eigen::Index(i), k) = rows[i][size_t(k)];
      (*b)[Eigen::Index(i)] = rows[i][6];
    }
  };
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  design(hw, hh, true, &a, &b);
  const double full_variance = (a.transpose() * a).inverse()(0, 0);
  int compared = 0, compared_at_band_edges = 0;
  double worst = 0;
  for (int y = hh; y < d.rows - hh; ++y)
    for (int x = hw; x < d.cols - hw; ++x) {
      if (!std::isfinite(raw.at<float>(y, x))) continue;
      design(x, y, false, &a, &b);
      const double ratio = (a.transpose() * a).inverse()(0, 0) / full_variance;
      // Away from the variance gate (the fit's float sums could fall either
      // side of it); no window of this smooth field fails the misfit gate.
      if (std::abs(ratio - o.max_variance_growth) < 0.05) continue;
      const double plain = a.colPivHouseholderQr().solve(b)[0];
      if (ratio > o.max_variance_growth) {
        EXPECT_EQ(d.at<float>(y, x), raw.at<float>(y, x)) << "an extrapolating window leaves the pixel alone";
        continue;
      }
      ++compared;
      for (const int edge : {128, 256})
        if (y >= edge - hh - 1 && y <= edge + hh) ++compared_at_band_edges;  // its window spans two bands
      worst = std::max(worst, std::abs(d.at<float>(y, x) - plain));
    }
  std::printf("%d windows with holes (%d across band edges): |fit - plain least squares| max %.2e px\n", compared,
              compared_at_band_edges, worst);
  EXPECT_GT(compared, 8000);
  EXPECT_GT(compared_at_band_edges, 1000);
  // Float window sums of values of 40-80 px (~1e-7
  // relative) and the float result: well below 1e-4 px. A wrong moment or
  // term would be off by the noise's scale, 0.01-0.3 px.
  EXPECT_LT(worst, 1e-4);
}

// The fitted centre's variance for independent errors of unit variance and
// a full (2 hw + 1) x (2 hh + 1) window: (A^T A)^-1 [0, 0] of the quadric's
// design matrix (constant term first), by Eigen.
double CentreVarianceFactor(int hw, int hh) {
  Eigen::MatrixXd a((2 * hw + 1) * (2 * hh + 1), 6);
  int i = 0;
  for (int v = -hh; v <= hh; ++v)
    for (int u = -hw; u <= hw; ++u, ++i) {
      const double su = double(u) / hw, sv = double(v) / hh;
      a.row(i) << 1, su, sv, su * su, su * sv, sv * sv;
    }
  return (a.transpose() * a).inverse()(0, 0);
}

// The rms of the fitted field against the truth over pixels whose
// (2 hw + 1) x (2 hh + 1) window is inside the image.
double InteriorRms(const cv::Mat& d, const cv::Mat& truth, int hw, int hh) {
  double sum2 = 0;
  int n = 0;
  for (int y = hh; y < d.rows - hh; ++y)
    for (int x = hw; x < d.cols - hw; ++x, ++n) sum2 += std::pow(d.at<float>(y, x) - truth.at<float>(y, x), 2);
  return std::sqrt(sum2 / n);
}

// Noise sqrt(2) times the reference misfit: the window's sides grow by the
// ratio squared, 2 (41 x 21, 3.7x the area), and the fitted field's scatter
// is what least squares predicts for that window, ~half the default
// window's. Noise below the reference: the result is exactly the one
// window's.
TEST(LocalSurfaceFit, GrowsItsWindowWithTheMeasuredNoise) {
  cv::Mat truth(240, 400, CV_32F);
  for (int y = 0; y < truth.rows; ++y)
    for (int x = 0; x < truth.cols; ++x) {  // the quadric above, stretched 2x (a flatter surface)
      const double u = x / 2.0 - 100.0, v = y / 2.0 - 60.0;
      truth.at<float>(y, x) = float(40 + 0.05 * u - 0.02 * v + 4e-4 * u * u + 2e-4 * u * v + 6e-4 * v * v);
    }
  auto noisy = [&](double sigma_px, uint64_t seed) {
    cv::Mat d = truth.clone();
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0, sigma_px);
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) += float(noise(rng));
    return d;
  };
  const cv::Rect all(0, 0, truth.cols, truth.rows);
  SurfaceFitOptions fixed;
  fixed.reference_misfit_px = 0;
  SurfaceFitOptions adaptive;
  adaptive.reference_misfit_px = 0.2;

  // Independent errors: the median misfit is ~sigma, sqrt(2) times the reference.
  const double sigma_px = 0.2 * std::sqrt(2.0);
  const cv::Mat raw = noisy(sigma_px, 3);
  cv::Mat one = raw.clone(), grown = raw.clone();
  FitLocalSurface(all, fixed, 2, &one);
  SurfaceFitSummary summary;
  FitLocalSurface(all, adaptive, 2, &grown, &summary);
  // The median of a chi distribution with ~225 degrees of freedom, over ~90 000
  // windows: sigma within ~0.5 %, the ratio squared within ~1 % of 2 (the
  // sides round to 20 and 10 from 19.5 to 20.5 and 9.75 to 10.25).
  EXPECT_NEAR(summary.median_misfit_px, sigma_px, 0.02 * sigma_px);
  EXPECT_EQ(summary.half_width_px, 20);
  EXPECT_EQ(summary.half_height_px, 10);
  // Both measured where the wide window is full. The rms over N ~ 79 000
  // pixels scatters by ~1/sqrt(2 N_eff) relative, N_eff ~ N / window area
  // (neighbouring fits share their data): 4 % for 21 x 11, 7.4 % for
  // 41 x 21; 3 of the latter.
  const double rms_one = InteriorRms(one, truth, 20, 10), rms_grown = InteriorRms(grown, truth, 20, 10);
  const double predicted_one = sigma_px * std::sqrt(CentreVarianceFactor(10, 5));
  const double predicted_grown = sigma_px * std::sqrt(CentreVarianceFactor(20, 10));
  EXPECT_NEAR(rms_one, predicted_one, 0.24 * predicted_one);
  EXPECT_NEAR(rms_grown, predicted_grown, 0.24 * predicted_grown);
  EXPECT_LT(rms_grown, 0.7 * rms_one);  // predicted 0.51
  std::printf("noise %.2f px: 21x11 %.4f px rms (predicted %.4f), grown %.4f (41x21 predicted %.4f)\n", sigma_px,
              rms_one, predicted_one, rms_grown, predicted_grown);

  const cv::Mat quiet = noisy(0.1, 4);  // half the reference
  cv::Mat quiet_one = quiet.clone(), quiet_adaptive = quiet.clone();
  FitLocalSurface(all, fixed, 2, &quiet_one);
  FitLocalSurface(all, adaptive, 2, &quiet_adaptive, &summary);
  EXPECT_EQ(summary.half_width_px, 10);
  EXPECT_EQ(summary.half_height_px, 5);
  EXPECT_EQ(cv::norm(quiet_one, quiet_adaptive, cv::NORM_INF), 0.0);
}

// A patch a few pixels across and 3 px off (a wrong alignment the line
// index left, a seam) misfits its own window, so it keeps its disparities;
// the grown window would dilute it (its misfit there is under the gate),
// so the wide fit is taken only where the own window's is trusted too.
TEST(LocalSurfaceFit, APatchItsOwnWindowRejectsStaysOutOfTheGrownFit) {
  cv::Mat d(240, 400, CV_32F);
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0, 0.4);  // twice the reference: the window grows
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) = float(40 + 0.01 * x + noise(rng));
  std::vector<cv::Rect> patches;
  for (int k = 0; k < 5; ++k) patches.emplace_back(60 + 60 * k, 100, 6, 4);
  for (const cv::Rect& p : patches) d(p) += 3.0;
  const cv::Mat raw = d.clone();
  SurfaceFitOptions adaptive;
  adaptive.reference_misfit_px = 0.2;
  FitLocalSurface(cv::Rect(0, 0, d.cols, d.rows), adaptive, 2, &d);
  int kept = 0, total = 0;
  for (const cv::Rect& p : patches)
    for (int y = p.y; y < p.y + p.height; ++y)
      for (int x = p.x; x < p.x + p.width; ++x, ++total) kept += d.at<float>(y, x) == raw.at<float>(y, x);
  EXPECT_EQ(kept, total) << "patch pixels smoothed into the surface around them";
  // Far from the patches the wide fit is taken: scatter well under the
  // 21 x 11 window's (0.4 * sqrt(0.0153) = 0.049 px).
  double sum2 = 0;
  int n = 0;
  for (int y = 150; y < 230; ++y)
    for (int x = 20; x < 380; ++x, ++n) sum2 += std::pow(d.at<float>(y, x) - (40 + 0.01 * x), 2);
  EXPECT_LT(std::sqrt(sum2 / n), 0.7 * 0.049);
}

}  // namespace
}  // namespace stereorig
