// The truth fill target against geometry written here: a plane in front of
// the default rig's module 0, its depth maps computed in closed form per
// camera (ray-plane intersection through Camera::Unproject), with an
// occluder strip in front of the right camera only and an unlit band.
#include "reconstruct/fill_score.h"

#include <gtest/gtest.h>

#include "datasets/default_rig.h"

namespace stereorig {
namespace {

// Depth map (z, camera frame) of the plane n.p = c given in `cam_from_left`'s
// source frame (the left camera), for every pixel of `cam`.
cv::Mat PlaneDepth(const Camera& cam, const Pose& cam_from_left, const Eigen::Vector3d& n_left, double c_left) {
  cv::Mat depth(cam.imager_height_px(), cam.imager_width_px(), CV_32FC1, cv::Scalar(0));
  const Pose left_from_cam = cam_from_left.Inverse();
  const Eigen::Vector3d o = left_from_cam.translation_mm();
  for (int r = 0; r < depth.rows; ++r) {
    Eigen::Matrix<double, Eigen::Dynamic, 2> q(depth.cols, 2);
    for (int x = 0; x < depth.cols; ++x) q.row(x) << x, r;
    const Eigen::Matrix<double, Eigen::Dynamic, 3> v = cam.UnprojectMany(q);
    for (int x = 0; x < depth.cols; ++x) {
      const Eigen::Vector3d v_cam = v.row(x).transpose();
      const Eigen::Vector3d d = left_from_cam.rotation() * v_cam;
      const double t = (c_left - n_left.dot(o)) / n_left.dot(d);
      if (t > 0) depth.at<float>(r, x) = float(t * v_cam.z());
    }
  }
  return depth;
}

TEST(FillScore, TargetIsObjectSeenByBothCamerasAndLit) {
  const SimulatedRig sim = MakeDefaultRig();
  const Rig& rig = sim.rig;
  const StereoModule& mod = rig.module(0);
  const Camera& left = rig.camera(mod.left_camera);
  const Camera& right = rig.camera(mod.right_camera);
  // A plane facing module 0 at z = 200 mm (left camera frame).
  const Eigen::Vector3d n(0, 0, 1);
  const double c = 200;
  CameraTruthMaps l, r;
  l.depth_mm = PlaneDepth(left, Pose(), n, c);
  r.depth_mm = PlaneDepth(right, mod.right_from_left, n, c);
  l.id = cv::Mat(l.depth_mm.size(), CV_8UC1, cv::Scalar(1));
  r.id = l.id.clone();
  l.lit = cv::Mat(l.depth_mm.size(), CV_8UC1, cv::Scalar(1));
  r.lit = l.lit.clone();
  // Unlit: the left image's rows 0..99.
  l.lit.rowRange(0, 100).setTo(0);
  // An occluder in front of the right camera only: its columns 300..349 see
  // something 50 mm closer.
  r.depth_mm.colRange(300, 350) -= 50.0f;
  const cv::Mat target = FillTargetMask(rig, 0, l, r);
  int checked = 0, wrong = 0;
  for (int y = 0; y < target.rows; y += 3)
    for (int x = 0; x < target.cols; x += 3) {
      // Independent expectation: where the plane point lands in the right
      // camera (Camera::Project), and whether that is inside the image and
      // off the occluder's columns.
      Eigen::Vector3d v;
      ASSERT_TRUE(left.Unproject(Eigen::Vector2d(x, y), &v));
      const Eigen::Vector3d p_right = mod.right_from_left * (v * (c / v.z()));
      const Eigen::Vector2d q = right.Project(p_right);
      const bool inside =
          q.x() > 0.5 && q.y() > 0.5 && q.x() < right.imager_width_px() - 1.5 && q.y() < right.imager_height_px() - 1.5;
      const bool near_occluder = q.x() > 297 && q.x() < 352;  // the 4-pixel test's reach
      const bool near_edge =
          q.x() < 2 || q.y() < 2 || q.x() > right.imager_width_px() - 3 || q.y() > right.imager_height_px() - 3;
      if (near_edge || (near_occluder && !(q.x() > 301 && q.x() < 348))) continue;  // ambiguous borders
      const bool expected = y >= 100 && inside && !near_occluder;
      wrong += expected != (target.at<uint8_t>(y, x) != 0);
      ++checked;
    }
  EXPECT_GT(checked, 20000);  // of 48 700 sampled pixels; the rest see past the right view or sit on a border
  EXPECT_EQ(wrong, 0);
}

TEST(FillScore, CountsPointsOnTargetPixelsThroughTheMap) {
  // Rectified 4x3 grid mapping to original pixels (x + 10, y + 20).
  cv::Mat map_x(3, 4, CV_32FC1), map_y(3, 4, CV_32FC1);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) map_x.at<float>(y, x) = x + 10.2f, map_y.at<float>(y, x) = y + 19.8f;
  cv::Mat target(40, 40, CV_8UC1, cv::Scalar(0));
  target(cv::Rect(10, 20, 2, 3)).setTo(255);  // rectified columns 0 and 1
  cv::Mat status(3, 4, CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kLowZncc)));
  status.at<uint8_t>(0, 0) = uint8_t(PixelStatus::kPoint);
  status.at<uint8_t>(1, 1) = uint8_t(PixelStatus::kPoint);
  status.at<uint8_t>(2, 3) = uint8_t(PixelStatus::kPoint);  // off target
  const FillFigures f = ScoreFill(status, map_x, map_y, target);
  EXPECT_EQ(f.target_px, 6);
  EXPECT_EQ(f.filled_px, 2);
  EXPECT_EQ(f.other_px, 1);
  EXPECT_EQ(f.target_status[size_t(PixelStatus::kLowZncc)], 4);
  EXPECT_DOUBLE_EQ(f.fill(), 2.0 / 6.0);
}

}  // namespace
}  // namespace stereorig
