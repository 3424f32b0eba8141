#include "datasets/calibration_poses.h"

#include <Eigen/Geometry>
#include <cmath>

#include "datasets/rng.h"

namespace stereorig {

std::vector<Pose> MakeCalibrationPoses(const CalibrationSpec& spec, const PhysicalBoard& board,
                                       const std::vector<Camera>& cameras, const std::vector<Pose>& world_from_camera,
                                       uint64_t seed) {
  Rng rng(seed);
  const Target& t = *board.target;
  const Eigen::Vector3d center_front(0.5 * (t.corners_x() - 1) * t.square_size_mm(),
                                     0.5 * (t.corners_y() - 1) * t.square_size_mm(), 0);
  const double deg = M_PI / 180.0;
  std::vector<Pose> poses;
  for (int k = 0; k < spec.captures; ++k) {
    Pose best;
    int best_min = -1;
    for (int attempt = 0; attempt < 200; ++attempt) {
      // A 3x3 grid over x-y (cell k mod 9), jittered within its cell; after
      // 20 failed draws the cell constraint is dropped.
      const int cell = k % 9;
      const double fx = attempt < 20 ? ((cell % 3) + rng.Uniform()) / 3.0 : rng.Uniform();
      const double fy = attempt < 20 ? ((cell / 3) + rng.Uniform()) / 3.0 : rng.Uniform();
      const Eigen::Vector3d c((fx - 0.5) * spec.volume_mm.x(), (fy - 0.5) * spec.volume_mm.y(),
                              rng.Uniform(-0.5, 0.5) * spec.volume_mm.z());
      // Tilt: a direction in the board plane and an angle up to the maximum,
      // uniform over the disc of (tilt_x, tilt_y).
      double ax, ay;
      do {
        ax = rng.Uniform(-1, 1);
        ay = rng.Uniform(-1, 1);
      } while (ax * ax + ay * ay > 1);
      const double roll = rng.Uniform(-spec.roll_max_deg, spec.roll_max_deg) * deg;
      const Eigen::Matrix3d r = (Eigen::AngleAxisd(ax * spec.tilt_max_deg * deg, Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(ay * spec.tilt_max_deg * deg, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
                                    .toRotationMatrix();
      // Front frame: x right, y down, z away from module 0 (world +z).
      const Pose world_from_front(r, c - r * center_front);
      int min_seen = 1 << 30;
      for (size_t i = 0; i < cameras.size(); ++i) {
        min_seen = std::min(min_seen, CornersInView(cameras[i], world_from_camera[i], world_from_front, board));
      }
      if (min_seen > best_min) {
        best_min = min_seen;
        best = world_from_front;
      }
      if (min_seen >= spec.min_corners_per_camera) break;
    }
    poses.push_back(best);
  }
  return poses;
}

}  // namespace stereorig
