// The board's pose from calibrated cameras (board_pose.h): the analytic
// corner Jacobian against central differences taken through another
// rotation (Eigen's angle-axis, not Ceres'), and the pose itself against
// the truth it was rendered from.
#include "calib/check/board_pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "datasets/default_rig.h"

namespace stereorig {
namespace {

// Camera 0 sees the board's centre `distance_mm` ahead, turned by
// `tilt_rad` about (1, 1, 0): the board pose in the rig's reference frame.
Pose BoardAhead(const Rig& rig, const Target& target, double distance_mm, double tilt_rad) {
  const Eigen::Vector3d centre((target.corners_x() - 1) * 0.5 * target.square_size_mm(),
                               (target.corners_y() - 1) * 0.5 * target.square_size_mm(), 0);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Pose cam_from_front(r, Eigen::Vector3d(0, 0, distance_mm) - r * centre);
  return rig.CamFromReference(0).Inverse() * cam_from_front;
}

// Central differences of Camera::Project through Pose::FromRotationVector:
// with steps of 1e-6 rad and 1e-4 mm, truncation (h^2 of a third
// derivative: ~1e-12 x 1e4 px/rad) and rounding (1e-16 x 1e3 px / h) stay
// under 1e-6 of a column's size (~1e3-1e4 px/rad, ~5 px/mm) plus 1e-8
// (a column that is zero: the board's origin turned about itself, its
// centre moved along camera 0's axis), where a sign or a frame wrong in the
// chain rule is off by the column itself.
TEST(BoardPose, TheCornerJacobianIsTheProjectionsCentralDifference) {
  const Rig rig = MakeDefaultRig().rig;
  const Target target = DefaultTarget();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> tilt(-0.6, 0.6);
  int compared = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const Pose ref_from_front = BoardAhead(rig, target, 180 + 10 * trial, tilt(rng));
    const Eigen::Vector3d r = ref_from_front.RotationVector(), t = ref_from_front.translation_mm();
    const double rt[6] = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
    for (int camera : {0, 1}) {
      const Pose cam_from_ref = rig.CamFromReference(camera);
      for (int id = 0; id < target.num_corners(); id += 7) {
        const Eigen::Vector3d p = target.CornerInFace(id);
        Eigen::Vector2d q;
        Eigen::Matrix<double, 2, 6> j;
        ASSERT_TRUE(ProjectBoardCorner(rig.camera(camera), cam_from_ref, rt, p, &q, &j));
        const auto project = [&](const Eigen::Matrix<double, 6, 1>& x) {
          return rig.camera(camera).Project(cam_from_ref * (Pose::FromRotationVector(x.head<3>(), x.tail<3>()) * p));
        };
        Eigen::Matrix<double, 6, 1> x;
        x << r, t;
        EXPECT_LT((q - project(x)).norm(), 1e-9) << "camera " << camera << ", corner " << id;
        for (int k = 0; k < 6; ++k) {
          const double h = k < 3 ? 1e-6 : 1e-4;
          Eigen::Matrix<double, 6, 1> plus = x, minus = x;
          plus[k] += h;
          minus[k] -= h;
          const Eigen::Vector2d numeric = (project(plus) - project(minus)) / (2 * h);
          EXPECT_LE((j.col(k) - numeric).norm(), 1e-6 * numeric.norm() + 1e-8)
              << "camera " << camera << ", corner " << id << ", parameter " << k << ": " << j.col(k).transpose()
              << " vs " << numeric.transpose();
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 10 * 2 * 6 * ((target.num_corners() + 6) / 7));
  // Behind the camera: not projected.
  const Pose behind = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -400)) * BoardAhead(rig, target, 200, 0);
  const Eigen::Vector3d r = behind.RotationVector(), t = behind.translation_mm();
  const double rt[6] = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
  Eigen::Vector2d q;
  EXPECT_FALSE(ProjectBoardCorner(rig.camera(0), rig.CamFromReference(0), rt, target.CornerInFace(0), &q, nullptr));
}

// Noiseless corners of both cameras of module 0, the solve seeded 2 degrees
// and 3 mm off: the truth comes back to what the solver's tolerances leave
// (parameter_tolerance 1e-12, relative), far under the 1e-6 mm / 1e-8 rad
// asked; a Jacobian wrong in sign or frame stops elsewhere or not at all.
TEST(BoardPose, NoiselessCornersGiveTheTruePoseFromAnOffSeed) {
  const Rig rig = MakeDefaultRig().rig;
  const Target target = DefaultTarget();
  for (double tilt_rad : {0.0, 0.3, -0.5}) {
    const Pose truth = BoardAhead(rig, target, 200, tilt_rad);
    std::vector<BoardObservation> views(2);
    for (int camera : {0, 1}) {
      BoardObservation& v = views[camera];
      v.capture = 0;
      v.camera = camera;
      const Pose cam_from_front = rig.CamFromReference(camera) * truth;
      for (int id = 0; id < target.num_corners(); ++id) {
        v.corner_ids.push_back(id);
        v.q_px.push_back(rig.camera(camera).Project(cam_from_front * target.CornerInFace(id)));
      }
    }
    const Pose seed = Pose::FromRotationVector(truth.RotationVector() + Eigen::Vector3d(0.035, 0, 0),
                                               truth.translation_mm() + Eigen::Vector3d(3, 0, 0));
    const BoardPoseEstimate e = EstimateBoardPose(rig, target, {&views[0], &views[1]}, &seed);
    ASSERT_TRUE(e.ok) << tilt_rad;
    EXPECT_LT((e.ref_from_front.translation_mm() - truth.translation_mm()).norm(), 1e-6) << tilt_rad;
    EXPECT_LT((e.ref_from_front.RotationVector() - truth.RotationVector()).norm(), 1e-8) << tilt_rad;
    EXPECT_LT(e.rms_px, 1e-6) << tilt_rad;
    EXPECT_EQ(e.num_corners, 2 * target.num_corners());
  }
}

}  // namespace
}  // namespace stereorig
