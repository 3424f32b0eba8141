// The local plane fit (local_plane.h) and the validity bitmap it reads
// (validity_bits.h): against an analytic plane, and bit for bit against the
// Eigen fit growing used before (kept here as the reference), on random
// windows in every regime (the exact eight-column sums and the raster-order
// fallback: disparities tiny, huge, zero, negative zero).
#include "reconstruct/local_plane.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "reconstruct/validity_bits.h"

namespace stereorig {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Growing's plane fit as it was (region_grow.cc until session 8).
bool ReferencePlane(const cv::Mat& disparity, const cv::Rect& roi, cv::Point q, int r, double* a, double* gx,
                    double* gy) {
  const int v0 = std::max(-r, roi.y - q.y), v1 = std::min(r, roi.y + roi.height - 1 - q.y);
  const int u0 = std::max(-r, roi.x - q.x), u1 = std::min(r, roi.x + roi.width - 1 - q.x);
  int n = 0, nx = 0, ny = 0, nxx = 0, nyy = 0, nxy = 0;
  double sd = 0, sxd = 0, syd = 0;
  for (int v = v0; v <= v1; ++v) {
    const float* row = disparity.ptr<float>(q.y + v) + q.x;
    for (int u = u0; u <= u1; ++u) {
      const float d = row[u];
      if (!std::isfinite(d)) continue;
      ++n, nx += u, ny += v, nxx += u * u, nyy += v * v, nxy += u * v;
      sd += d, sxd += u * d, syd += v * d;
    }
  }
  const double s1 = n, sx = nx, sy = ny, sxx = nxx, syy = nyy, sxy = nxy;
  if (s1 < 6) return false;
  Eigen::Matrix3d m;
  m << s1, sx, sy, sx, sxx, sxy, sy, sxy, syy;
  if (std::abs(m.determinant()) < 1e-6 * s1 * s1 * s1) return false;
  const Eigen::Vector3d p = m.ldlt().solve(Eigen::Vector3d(sd, sxd, syd));
  if (!p.allFinite()) return false;
  *a = p[0], *gx = p[1], *gy = p[2];
  return true;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A disparity in one of the regimes the fit must reproduce bit for bit.
float RandomDisparity(cv::RNG& rng, int regime) {
  switch (regime) {
    case 0:  // the demo's range, -100 .. 174 px
      return float(rng.uniform(-100.0, 174.0));
    case 1:  // near 0: some below the exact sums' 2^-8 (the fallback)
      return float(rng.uniform(-0.02, 0.02));
    case 2: {  // huge, tiny and zeros mixed
      const int k = rng.uniform(0, 5);
      return k == 0 ? 0.0f : k == 1 ? -0.0f : k == 2 ? float(rng.uniform(400.0, 3000.0)) : float(rng.gaussian(1e-4));
    }
    default:  // integers and halves: many equal values
      return float(rng.uniform(-40, 40)) * 0.5f;
  }
}

TEST(LocalPlane, RecoversAnAnalyticPlaneFromItsValidPixels) {
  // d = 37.5 + 0.3 (x - 50) - 0.2 (y - 40) on a random 3/4 of the pixels
  // (a corner's window, clipped to 4x4, holds about 12). The disparities
  // are stored as floats (ulp at ~40 px: 3.8e-6): the fit of 10-40 of them
  // is good to ~1e-5 px and 1e-5 px/px.
  cv::RNG rng(11);
  cv::Mat disparity(80, 100, CV_32FC1, cv::Scalar(kNaN));
  for (int y = 0; y < disparity.rows; ++y)
    for (int x = 0; x < disparity.cols; ++x)
      if (rng.uniform(0, 4) != 0) disparity.at<float>(y, x) = float(37.5 + 0.3 * (x - 50) - 0.2 * (y - 40));
  const cv::Rect roi(0, 0, 100, 80);
  const ValidityBits valid(disparity, roi);
  for (const cv::Point q : {cv::Point(50, 40), cv::Point(0, 0), cv::Point(99, 79), cv::Point(3, 77)}) {
    LocalPlane plane;
    ASSERT_TRUE(FitLocalPlane(disparity, valid, roi, q, 3, &plane));
    EXPECT_NEAR(plane.disparity_px, 37.5 + 0.3 * (q.x - 50) - 0.2 * (q.y - 40), 1e-5);
    EXPECT_NEAR(plane.slope_x, 0.3, 1e-5);
    EXPECT_NEAR(plane.slope_y, -0.2, 1e-5);
  }
  // Five valid pixels are too few, six on a line degenerate: untouched.
  disparity.setTo(kInf);
  for (int x = 40; x < 46; ++x) disparity.at<float>(40, x) = 10;
  const ValidityBits line(disparity, roi);
  LocalPlane plane{1, 2, 3};
  EXPECT_FALSE(FitLocalPlane(disparity, line, roi, {42, 41}, 3, &plane));
  EXPECT_EQ(plane.disparity_px, 1);
}

TEST(LocalPlane, EqualsTheEigenFitBitForBitOnRandomWindows) {
  cv::RNG rng(5);
  int fitted = 0, compared = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int regime = trial % 4;
    cv::Mat disparity(60, 150, CV_32FC1);
    const double density = rng.uniform(0.05, 1.0);
    for (int y = 0; y < disparity.rows; ++y)
      for (int x = 0; x < disparity.cols; ++x)
        disparity.at<float>(y, x) = rng.uniform(0.0, 1.0) < density ? RandomDisparity(rng, regime)
                                    : rng.uniform(0, 2)             ? kInf
                                                                    : kNaN;
    // Rois ending at the image's last column and row too (the fit's
    // reads there must stay inside).
    const int x0 = rng.uniform(0, 70), y0 = rng.uniform(0, 30);
    const cv::Rect roi(x0, y0, rng.uniform(1, disparity.cols - x0 + 1), rng.uniform(1, disparity.rows - y0 + 1));
    const ValidityBits valid(disparity, roi);
    for (int k = 0; k < 50; ++k) {
      const cv::Point q(roi.x + rng.uniform(0, roi.width), roi.y + rng.uniform(0, roi.height));
      const int r = rng.uniform(1, 11);
      double a = 0, gx = 0, gy = 0;
      const bool expected = ReferencePlane(disparity, roi, q, r, &a, &gx, &gy);
      LocalPlane plane{-7, -7, -7};
      const bool got = FitLocalPlane(disparity, valid, roi, q, r, &plane);
      ++compared;
      ASSERT_EQ(got, expected) << "trial " << trial << " q " << q << " r " << r;
      if (!got) continue;
      ++fitted;
      ASSERT_TRUE(SameBits(plane.disparity_px, a) && SameBits(plane.slope_x, gx) && SameBits(plane.slope_y, gy))
          << "trial " << trial << " q " << q << " r " << r << ": " << plane.disparity_px << " " << plane.slope_x << " "
          << plane.slope_y << " vs " << a << " " << gx << " " << gy;
    }
  }
  EXPECT_GT(fitted, compared / 2);  // most windows fit: the comparison is not vacuous
}

TEST(LocalPlane, SolveEqualsEigenLdltBitForBit) {
  // Symmetric matrices of every kind the pivoting meets: definite,
  // indefinite, singular, with equal diagonals (first of equals pivots).
  cv::RNG rng(9);
  for (int trial = 0; trial < 20000; ++trial) {
    double m[3][3];
    const int kind = trial % 4;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) {
        double v = kind == 0   ? rng.uniform(-10.0, 10.0)
                   : kind == 1 ? double(rng.uniform(-3, 4))
                   : kind == 2 ? rng.gaussian(1.0) * std::pow(10.0, rng.uniform(-6, 7))
                               : double(rng.uniform(0, 2));
        m[i][j] = m[j][i] = v;
      }
    if (kind == 3) m[1][1] = m[2][2] = m[0][0];
    const double b[3] = {rng.uniform(-100.0, 100.0), rng.gaussian(1000.0), double(rng.uniform(-5, 6))};
    Eigen::Matrix3d em;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) em(i, j) = m[i][j];
    const Eigen::Vector3d expected = em.ldlt().solve(Eigen::Vector3d(b[0], b[1], b[2]));
    double p[3];
    internal::SolveLdlt3(m, b, p);
    for (int i = 0; i < 3; ++i)
      ASSERT_TRUE(SameBits(p[i], expected[i]) || (std::isnan(p[i]) && std::isnan(expected[i])))
          << "trial " << trial << " component " << i << ": " << p[i] << " vs " << expected[i];
  }
}

TEST(ValidityBits, MatchesTheMapAndFindsItsEdgePixels) {
  cv::RNG rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    cv::Mat disparity(40, 200, CV_32FC1);
    const double density = rng.uniform(0.0, 1.0);
    for (int y = 0; y < disparity.rows; ++y)
      for (int x = 0; x < disparity.cols; ++x)
        disparity.at<float>(y, x) = rng.uniform(0.0, 1.0) < density ? float(rng.uniform(-5.0, 5.0)) : kNaN;
    const int x0 = rng.uniform(0, 100), y0 = rng.uniform(0, 20);
    const cv::Rect roi(x0, y0, rng.uniform(1, disparity.cols - x0 + 1), rng.uniform(1, disparity.rows - y0 + 1));
    ValidityBits valid(disparity, roi);
    auto finite = [&](int x, int y) { return std::isfinite(disparity.at<float>(y, x)); };
    // Set keeps it in step with writes.
    for (int k = 0; k < 20; ++k) {
      const int x = roi.x + rng.uniform(0, roi.width), y = roi.y + rng.uniform(0, roi.height);
      disparity.at<float>(y, x) = rng.uniform(0, 2) ? 1.0f : kInf;
      valid.Set(x, y, finite(x, y));
    }
    std::vector<cv::Point> expected;
    for (int y = roi.y; y < roi.y + roi.height; ++y)
      for (int x = roi.x; x < roi.x + roi.width; ++x) {
        ASSERT_EQ(valid.Test(x, y), finite(x, y));
        const int count = std::min(63, roi.x + roi.width - x);
        const uint64_t span = valid.Span(x, y, count);
        for (int i = 0; i < count; ++i) ASSERT_EQ((span >> i) & 1, uint64_t(finite(x + i, y))) << x << " " << i;
        if (finite(x, y) && ((x > roi.x && !finite(x - 1, y)) || (x + 1 < roi.x + roi.width && !finite(x + 1, y)) ||
                             (y > roi.y && !finite(x, y - 1)) || (y + 1 < roi.y + roi.height && !finite(x, y + 1))))
          expected.emplace_back(x, y);
      }
    EXPECT_EQ(valid.EdgePixels(), expected);
  }
}

}  // namespace
}  // namespace stereorig
