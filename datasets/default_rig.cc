#include "datasets/default_rig.h"

#include <cmath>

namespace stereorig {

namespace {

// Per-camera lens: nominal focal length and centre, with the small
// manufacturing spread a real set of lenses has, and mild barrel distortion.
Camera MakeCamera(const DefaultRigGeometry& g, int index) {
  const double f_px = g.focal_length_mm / (g.pixel_pitch_um * 1e-3);
  // Deterministic, camera-specific offsets (no RNG: the default is fixed).
  const double df = 3.0 * std::sin(1.7 * index + 0.3);
  const double dcx = 4.0 * std::cos(2.3 * index + 0.1);
  const double dcy = 3.0 * std::sin(0.9 * index + 1.1);
  const double cx = 0.5 * (g.imager_width_px - 1) + dcx;
  const double cy = 0.5 * (g.imager_height_px - 1) + dcy;
  // OPENCV8: fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6.
  std::vector<double> intrinsics = {
      f_px + df, f_px + df + 0.4, cx, cy, -0.11 + 0.01 * index, 0.09, 2e-4, -1e-4, -0.02, 0.0, 0.0, 0.0};
  return Camera("LENSMODEL_OPENCV8", intrinsics, g.imager_width_px, g.imager_height_px, "default rig");
}

}  // namespace

SimulatedRig MakeDefaultRig(const DefaultRigGeometry& g) {
  const double half_verge = 0.5 * g.verging_deg * M_PI / 180.0;
  // In a module's nominal frame (origin midway between the cameras, z towards
  // the object), the left camera sits at x = -B/2 turned +half_verge about y
  // (towards +x), the right one at +B/2 turned -half_verge.
  const Pose nominal_from_left(Eigen::AngleAxisd(half_verge, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                               Eigen::Vector3d(-0.5 * g.baseline_mm, 0, 0));
  const Pose nominal_from_right(Eigen::AngleAxisd(-half_verge, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                Eigen::Vector3d(0.5 * g.baseline_mm, 0, 0));
  const Pose right_from_left = nominal_from_right.Inverse() * nominal_from_left;

  // World: object at the origin. Module 0's nominal frame at z = -WD looking
  // +z; module 1's at z = +WD looking -z (a half turn about y).
  const Pose world_from_nominal0(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -g.working_distance_mm));
  const Pose world_from_nominal1(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                 Eigen::Vector3d(0, 0, g.working_distance_mm));
  const Pose world_from_module0 = world_from_nominal0 * nominal_from_left;
  const Pose world_from_module1 = world_from_nominal1 * nominal_from_left;

  std::vector<Camera> cameras;
  std::vector<std::string> names;
  for (int i = 0; i < 4; ++i) {
    cameras.push_back(MakeCamera(g, i));
    names.push_back("cam" + std::to_string(i));
  }
  std::vector<StereoModule> modules = {{"module0", 0, 1, right_from_left}, {"module1", 2, 3, right_from_left}};
  const std::vector<Pose> module0_from_module = {Pose::Identity(), world_from_module0.Inverse() * world_from_module1};
  SimulatedRig out{Rig(std::move(cameras), std::move(names), std::move(modules), module0_from_module),
                   world_from_module0};
  out.rig.provenance().tool = "stereorig simulator (ground truth)";
  out.rig.provenance().input = "embedded default rig";
  return out;
}

}  // namespace stereorig
