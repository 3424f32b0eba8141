#include "calib/calib_test_util.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "calib/triangulation.h"

namespace stereorig::testing {

Pose DefaultVolume(const Pose& world_from_module0) { return world_from_module0.Inverse(); }

Eigen::Vector2d MeanFramesProjectionError(const Camera& truth, const std::vector<Pose>& true_cam_from_face,
                                          const Camera& solved, const std::vector<Pose>& solved_cam_from_face,
                                          const Eigen::Vector2d& q_px, double range_mm) {
  Eigen::Vector3d v;
  truth.Unproject(q_px, &v);
  const Eigen::Vector3d p_true = v.normalized() * range_mm;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < true_cam_from_face.size(); ++k) {
    mean += solved_cam_from_face[k] * (true_cam_from_face[k].Inverse() * p_true);
  }
  mean /= true_cam_from_face.size();
  return solved.Project(mean) - q_px;
}

}  // namespace stereorig::testing

namespace stereorig::testing {

std::vector<int> CapturesWhoseBoardPlaneSeparates(const Rig& truth, const std::vector<Pose>& ref_from_front,
                                                  const CalibrationInput& in, int camera_a, int camera_b) {
  std::map<int, int> seen;  // capture -> how many of the two cameras saw the board
  for (const BoardObservation& o : in.observations)
    if ((o.camera == camera_a || o.camera == camera_b) && !o.corner_ids.empty()) ++seen[o.capture];
  const Eigen::Vector3d centre_a = truth.CamFromReference(camera_a).Inverse().translation_mm();
  const Eigen::Vector3d centre_b = truth.CamFromReference(camera_b).Inverse().translation_mm();
  std::vector<int> out;
  for (const auto& [capture, n] : seen) {
    if (n < 2) continue;
    const Pose& board = ref_from_front.at(capture);
    const Eigen::Vector3d normal = board.rotation().col(2);
    const double side_a = normal.dot(centre_a - board.translation_mm());
    const double side_b = normal.dot(centre_b - board.translation_mm());
    if (side_a * side_b < 0) out.push_back(capture);
  }
  return out;
}

DefaultScene MakeDefaultScene(unsigned seed, int captures, double noise_px) {
  return MakeScene(MakeDefaultRig(), seed, captures, noise_px);
}

SimulatedRig MakeOneModuleRig() {
  const SimulatedRig d = MakeDefaultRig();
  std::vector<Camera> cams = {d.rig.camera(0), d.rig.camera(1)};
  SimulatedRig out{Rig(cams, {"cam0", "cam1"}, {d.rig.module(0)}, std::vector<Pose>{Pose::Identity()}),
                   d.world_from_module0};
  return out;
}

SimulatedRig MakeThreeModuleRig() {
  const SimulatedRig d = MakeDefaultRig();
  std::vector<Camera> cams = d.rig.cameras();
  // Two more cameras: the default's, with their own small differences.
  for (int c : {0, 1}) {
    std::vector<double> intr = d.rig.camera(c).intrinsics();
    intr[0] += 2.5, intr[1] += 2.2, intr[2] -= 3.0, intr[3] += 2.0, intr[4] += 0.01;
    cams.emplace_back(d.rig.camera(c).lensmodel_name(), intr, d.rig.camera(c).imager_width_px(),
                      d.rig.camera(c).imager_height_px());
  }
  std::vector<StereoModule> modules = d.rig.modules();
  StereoModule m2 = modules[0];
  m2.name = "module2";
  m2.left_camera = 4;
  m2.right_camera = 5;
  modules.push_back(m2);
  const Pose turn(Eigen::AngleAxisd(-30.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                  Eigen::Vector3d::Zero());
  const Pose world_from_module2 = turn * d.world_from_module0;
  const std::vector<Pose> module0_from_module = {Pose::Identity(), d.rig.S(0, 1),
                                                 d.world_from_module0.Inverse() * world_from_module2};
  SimulatedRig out{Rig(cams, {"cam0", "cam1", "cam2", "cam3", "cam4", "cam5"}, modules, module0_from_module),
                   d.world_from_module0};
  return out;
}

DefaultScene MakeScene(const SimulatedRig& rig, unsigned seed, int captures, double noise_px) {
  DefaultScene s{rig, Pose(), Pose(), {}};
  s.ref_from_volume = DefaultVolume(s.truth.world_from_module0);
  TargetGeometry told = DefaultTestTarget();
  s.true_back_from_front = told.back_from_front;
  std::mt19937 rng(seed * 7919u + 17u);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto& sg = told.back_from_front_sigma;
  const Eigen::Vector3d dr(sg(0) * n(rng), sg(1) * n(rng), sg(2) * n(rng));
  const Eigen::Vector3d dt(sg(3) * n(rng), sg(4) * n(rng), sg(5) * n(rng));
  told.back_from_front = Pose::FromRotationVector(dr * M_PI / 180.0, Eigen::Vector3d::Zero()) * told.back_from_front;
  told.back_from_front = Pose(told.back_from_front.rotation(), told.back_from_front.translation_mm() + dt);
  SyntheticOptions o;
  o.seed = seed;
  o.num_captures = captures;
  o.noise_px = noise_px;
  s.data = MakeSyntheticCaptures(s.truth.rig, told, s.true_back_from_front, s.ref_from_volume, o);
  return s;
}

std::vector<const BoardObservation*> ViewsOf(const CalibrationInput& in, int cam) {
  std::vector<const BoardObservation*> v;
  for (const auto& o : in.observations)
    if (o.camera == cam) v.push_back(&o);
  return v;
}

}  // namespace stereorig::testing
