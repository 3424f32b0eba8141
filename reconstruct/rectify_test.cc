// Rectification against mrcal's own projection: a 3D point's rectified
// pixels (left, and right at the same row shifted by its disparity) must map
// back, through the remap tables, to where Camera::Project puts the point in
// each original camera.
#include "reconstruct/rectify.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace stereorig {
namespace {

// Bilinear lookup of a CV_32FC1 table at a continuous pixel.
double Lookup(const cv::Mat& m, double u, double v) {
  const int x = int(std::floor(u)), y = int(std::floor(v));
  const double a = u - x, b = v - y;
  return (1 - a) * (1 - b) * m.at<float>(y, x) + a * (1 - b) * m.at<float>(y, x + 1) +
         (1 - a) * b * m.at<float>(y + 1, x) + a * b * m.at<float>(y + 1, x + 1);
}

TEST(Rectify, VergedDistortedPairMapsEveryPointOntoOneRow) {
  // A verged pair (6 deg), OPENCV8 distortion, slightly different lenses.
  const Camera left("LENSMODEL_OPENCV8", {1020, 1021, 378, 290, -0.11, 0.09, 2e-4, -1e-4, -0.02, 0, 0, 0}, 752, 582);
  const Camera right("LENSMODEL_OPENCV8", {1027, 1027.5, 371, 293, -0.10, 0.09, 1e-4, 2e-4, -0.02, 0, 0, 0}, 752, 582);
  const double verge = 6.0 * M_PI / 180;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(-verge, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                            Eigen::AngleAxisd(0.003, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d right_centre_left(90, 0.4, 1.0);
  const Pose right_from_left(r, -r * right_centre_left);
  const RectifiedGeometry g = ComputeRectification(left, right, right_from_left, Eigen::Vector3d(45, 0, 200));
  cv::Mat left_x, left_y, right_x, right_y;
  BuildRectifyMap(g, left, RectifiedView::kLeft, &left_x, &left_y);
  BuildRectifyMap(g, right, RectifiedView::kRight, &right_x, &right_y);
  EXPECT_NEAR(g.baseline_mm, right_centre_left.norm(), 1e-9);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(-30, 120), uy(-40, 40), uz(160, 240);
  int checked = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
    const Eigen::Vector3d q = g.PixelAndDisparity(g.rect_from_left * p);
    const double ul = q.x(), v = q.y(), ur = q.x() - q.z();
    if (ul < 1 || ur < 1 || v < 1 || ul > 750 || ur > 750 || v > 580) continue;
    const Eigen::Vector2d ql = left.Project(p), qr = right.Project(right_from_left * p);
    if (ql.x() < 0 || ql.x() > 751 || qr.x() < 0 || qr.x() > 751) continue;
    // The tables are sampled at whole pixels and interpolated bilinearly:
    // over one pixel the mapping is smooth to ~1e-3 px.
    EXPECT_NEAR(Lookup(left_x, ul, v), ql.x(), 2e-3);
    EXPECT_NEAR(Lookup(left_y, ul, v), ql.y(), 2e-3);
    EXPECT_NEAR(Lookup(right_x, ur, v), qr.x(), 2e-3);
    EXPECT_NEAR(Lookup(right_y, ur, v), qr.y(), 2e-3);
    // Triangulation inverts it.
    EXPECT_LT((g.Triangulate(ul, v, q.z()) - p).norm(), 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 80);
}

}  // namespace
}  // namespace stereorig
