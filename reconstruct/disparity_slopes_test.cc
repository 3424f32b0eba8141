// The local disparity plane (disparity_slopes.h): its exact integer window
// sums against cv::boxFilter of the masked moment images (the nine box
// filters it replaced), and the planes against analytic ones.
#include "reconstruct/disparity_slopes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>

namespace stereorig {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A map of the plane d = 50 + 0.3 x - 0.2 y with a share of its pixels
// invalid (NaN).
cv::Mat PlaneWithHoles(cv::Size size, double hole_share, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  cv::Mat d(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) d.at<float>(y, x) = u(rng) < hole_share ? kNaN : float(50 + 0.3 * x - 0.2 * y);
  return d;
}

// The window sum of one masked moment m(x, y) f(x, y) by cv::boxFilter, as
// the matcher took them (float images, zero border).
cv::Mat BoxSum(const cv::Mat& disparity, double (*f)(int x, int y)) {
  cv::Mat moment(disparity.size(), CV_32FC1);
  for (int y = 0; y < disparity.rows; ++y)
    for (int x = 0; x < disparity.cols; ++x)
      moment.at<float>(y, x) = std::isnan(disparity.at<float>(y, x)) ? 0.f : float(f(x, y));
  cv::Mat sum;
  const int k = 2 * kSlopeWindowHalfPx + 1;
  cv::boxFilter(moment, sum, CV_32F, cv::Size(k, k), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  return sum;
}

void ExpectBitEqual(const cv::Mat& a, const cv::Mat& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  ASSERT_EQ(a.type(), b.type()) << what;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x) ASSERT_EQ(a.at<float>(y, x), b.at<float>(y, x)) << what << " at " << x << "," << y;
}

TEST(DisparitySlopes, IntegerWindowSumsEqualBoxFilterToTheBit) {
  // Larger than the window, and smaller than it in each direction (every
  // window then reaches past two borders). Coordinates here stay below
  // 2^12, so the box filter's float moment images (x^2 < 2^24) are exact.
  for (const cv::Size size : {cv::Size(97, 61), cv::Size(5, 40), cv::Size(40, 3), cv::Size(1, 1)}) {
    const cv::Mat d = PlaneWithHoles(size, 0.3, 7);
    const MaskMomentSums s = WindowMaskMomentSums(d);
    ExpectBitEqual(s.n, BoxSum(d, [](int, int) { return 1.0; }), "n");
    ExpectBitEqual(s.x, BoxSum(d, [](int x, int) { return double(x); }), "x");
    ExpectBitEqual(s.y, BoxSum(d, [](int, int y) { return double(y); }), "y");
    ExpectBitEqual(s.xx, BoxSum(d, [](int x, int) { return double(x) * x; }), "xx");
    ExpectBitEqual(s.yy, BoxSum(d, [](int, int y) { return double(y) * y; }), "yy");
    ExpectBitEqual(s.xy, BoxSum(d, [](int x, int y) { return double(x) * y; }), "xy");
  }
}

// Maps wider than 4096 px take 64-bit sums (81 x^2 no longer fits 32
// bits): against the window sums added up plainly in double (exact: < 2^53).
TEST(DisparitySlopes, WideMapWindowSumsAreExact) {
  const cv::Mat d = PlaneWithHoles(cv::Size(4300, 11), 0.3, 5);
  const MaskMomentSums s = WindowMaskMomentSums(d);
  const int h = kSlopeWindowHalfPx;
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; x += 7) {
      double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      for (int v = std::max(0, y - h); v <= std::min(d.rows - 1, y + h); ++v)
        for (int u = std::max(0, x - h); u <= std::min(d.cols - 1, x + h); ++u) {
          if (std::isnan(d.at<float>(v, u))) continue;
          n += 1, sx += u, sy += v, sxx += double(u) * u, syy += double(v) * v, sxy += double(u) * v;
        }
      ASSERT_EQ(s.n.at<float>(y, x), float(n));
      ASSERT_EQ(s.x.at<float>(y, x), float(sx));
      ASSERT_EQ(s.y.at<float>(y, x), float(sy));
      ASSERT_EQ(s.xx.at<float>(y, x), float(sxx)) << x << "," << y;
      ASSERT_EQ(s.yy.at<float>(y, x), float(syy));
      ASSERT_EQ(s.xy.at<float>(y, x), float(sxy)) << x << "," << y;
    }
}

TEST(DisparitySlopes, RecoversAnAnalyticPlaneThroughHoles) {
  const cv::Mat d = PlaneWithHoles(cv::Size(120, 80), 0.4, 3);
  cv::Mat gx(d.size(), CV_32FC1, cv::Scalar(9)), gy(d.size(), CV_32FC1, cv::Scalar(9)), plane;
  DisparitySlopes(d, &gx, &gy, &plane);
  // Float rounding only (the map is an exact plane): the window sums of
  // x d reach ~81 * 120 * 80 ~ 8e5, whose float spacing is 1/16; over n >= 12
  // pixels and a coordinate variance >= ~2 px^2 that moves a slope by
  // < 1/16 / 12 / 2 ~ 3e-3 px/px, and the plane by that times the window's
  // half width (4 px).
  constexpr double kSlopeTol = 3e-3, kPlaneTolPx = 4 * kSlopeTol;
  int planes = 0;
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) {
      const float p = plane.at<float>(y, x);
      if (std::isnan(p)) {
        EXPECT_EQ(gx.at<float>(y, x), 0.f);
        EXPECT_EQ(gy.at<float>(y, x), 0.f);
        continue;
      }
      ++planes;
      EXPECT_NEAR(gx.at<float>(y, x), 0.3, kSlopeTol) << x << "," << y;
      EXPECT_NEAR(gy.at<float>(y, x), -0.2, kSlopeTol) << x << "," << y;
      EXPECT_NEAR(p, 50 + 0.3 * x - 0.2 * y, kPlaneTolPx) << x << "," << y;
    }
  // 60 % valid: 81 * 0.6 ~ 49 valid pixels in an inner window, ~20 in a
  // corner's 5x5 quarter: nearly every pixel has a plane.
  EXPECT_GT(planes, 0.95 * d.total());
}

TEST(DisparitySlopes, NoPlaneOnSparseWindowsOrDepthEdges) {
  // Only every third pixel of every third row valid: 9 per window < 12.
  cv::Mat sparse(30, 30, CV_32FC1, cv::Scalar(kNaN));
  for (int y = 0; y < sparse.rows; y += 3)
    for (int x = 0; x < sparse.cols; x += 3) sparse.at<float>(y, x) = 20;
  cv::Mat gx(sparse.size(), CV_32FC1), gy(sparse.size(), CV_32FC1), plane;
  DisparitySlopes(sparse, &gx, &gy, &plane);
  EXPECT_EQ(cv::countNonZero(plane == plane), 0) << "a window of 9 valid pixels has no plane";
  // A step of 40 px in disparity at x = 15: windows across it fit a slope
  // of several px/px (no surface), those clear of it a flat plane.
  cv::Mat step(30, 30, CV_32FC1);
  for (int y = 0; y < step.rows; ++y)
    for (int x = 0; x < step.cols; ++x) step.at<float>(y, x) = x < 15 ? 20 : 60;
  DisparitySlopes(step, &gx, &gy, &plane);
  EXPECT_TRUE(std::isnan(plane.at<float>(15, 15)));
  EXPECT_TRUE(std::isnan(plane.at<float>(15, 12)));
  EXPECT_NEAR(plane.at<float>(15, 5), 20, 1e-4);
  EXPECT_NEAR(gx.at<float>(15, 5), 0, 1e-5);
}

// The bound on dd/dx is one-sided (IsSurfaceSlope): a plane the left camera
// sees at a grazing angle slopes down the row without limit (the ring's
// oblique plate: -1.6 px/px), while a slope above 1 means the right camera
// sees the plane's back. Exact planes, so the fitted slopes are the
// analytic ones within RecoversAnAnalyticPlaneThroughHoles's float
// rounding.
TEST(DisparitySlopes, APlaneTheLeftCameraGrazesHasOneAndTheRightCamerasBackHasNone) {
  for (const double gx : {-1.6, -4.0, 1.6}) {
    cv::Mat d(40, 60, CV_32FC1);
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) = float(150 + gx * x + 0.02 * y);
    cv::Mat slope_x(d.size(), CV_32FC1), slope_y(d.size(), CV_32FC1), plane;
    DisparitySlopes(d, &slope_x, &slope_y, &plane);
    const int planes = cv::countNonZero(plane == plane);
    if (gx > 1) {
      EXPECT_EQ(planes, 0) << gx;
      continue;
    }
    EXPECT_EQ(planes, int(d.total())) << gx;
    EXPECT_NEAR(slope_x.at<float>(20, 30), gx, 3e-3) << gx;
    EXPECT_NEAR(plane.at<float>(20, 30), d.at<float>(20, 30), 1.2e-2) << gx;
  }
  EXPECT_TRUE(IsSurfaceSlope(-100, 0));
  EXPECT_TRUE(IsSurfaceSlope(kMaxSurfaceSlope, -kMaxSurfaceSlope));
  EXPECT_FALSE(IsSurfaceSlope(1.6, 0));
  EXPECT_FALSE(IsSurfaceSlope(0, -1.6));
}

}  // namespace
}  // namespace stereorig
