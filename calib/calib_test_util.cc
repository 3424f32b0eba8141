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

void TriangulateThroughModule(const Rig& truth, const Rig& calibrated, int k, const std::vector<Eigen::Vector3d>& p_ref,
                              std::vector<Eigen::Vector3d>* p_cal, std::vector<Eigen::Vector3d>* p_true,
                              std::vector<int>* used) {
  const StereoModule& tm = truth.module(k);
  const StereoModule& cm = calibrated.module(k);
  const Camera& tl = truth.camera(tm.left_camera);
  const Camera& tr = truth.camera(tm.right_camera);
  const Pose module_from_ref = truth.S(k, 0);
  p_cal->clear();
  p_true->clear();
  if (used) used->clear();
  for (size_t i = 0; i < p_ref.size(); ++i) {
    const Eigen::Vector3d pl = module_from_ref * p_ref[i];
    const Eigen::Vector3d pr = tm.right_from_left * pl;
    if (pl.z() <= 0 || pr.z() <= 0) continue;
    const Eigen::Vector2d ql = tl.Project(pl), qr = tr.Project(pr);
    auto inside = [](const Camera& c, const Eigen::Vector2d& q) {
      return q.x() >= 0 && q.y() >= 0 && q.x() <= c.imager_width_px() - 1 && q.y() <= c.imager_height_px() - 1;
    };
    if (!inside(tl, ql) || !inside(tr, qr)) continue;
    Eigen::Vector3d p;
    if (!TriangulatePair(calibrated.camera(cm.left_camera), calibrated.camera(cm.right_camera), cm.right_from_left, ql,
                         qr, &p)) {
      continue;
    }
    p_cal->push_back(p);
    p_true->push_back(pl);
    if (used) used->push_back(static_cast<int>(i));
  }
}

double RigidAlignedRms(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  Eigen::Matrix3Xd A(3, a.size()), B(3, b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    A.col(i) = a[i];
    B.col(i) = b[i];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(B, A, false);  // maps b onto a
  double s2 = 0;
  for (size_t i = 0; i < a.size(); ++i)
    s2 += (a[i] - (T.topLeftCorner<3, 3>() * b[i] + T.topRightCorner<3, 1>())).squaredNorm();
  return std::sqrt(s2 / a.size());
}

double ModuleAgreementRms(const Rig& truth, const Rig& calibrated, const Pose& i_from_j, int i, int j,
                          const std::vector<Eigen::Vector3d>& p_ref) {
  std::vector<Eigen::Vector3d> ci, ti, cj, tj;
  std::vector<int> ui, uj;
  TriangulateThroughModule(truth, calibrated, i, p_ref, &ci, &ti, &ui);
  TriangulateThroughModule(truth, calibrated, j, p_ref, &cj, &tj, &uj);
  std::map<int, Eigen::Vector3d> by_point;
  for (size_t n = 0; n < ui.size(); ++n) by_point[ui[n]] = ci[n];
  double s2 = 0;
  int count = 0;
  for (size_t n = 0; n < uj.size(); ++n) {
    auto it = by_point.find(uj[n]);
    if (it == by_point.end()) continue;
    s2 += (it->second - i_from_j * cj[n]).squaredNorm();
    ++count;
  }
  return count ? std::sqrt(s2 / count) : NAN;
}

}  // namespace stereorig::testing

namespace stereorig::testing {

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

}  // namespace stereorig::testing
