#include "calib/rig_compare.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "calib/core/input_error.h"

#include "calib/triangulation.h"

namespace stereorig {

namespace {

// "module 0 (m0)".
std::string ModuleName(const Rig& rig, int k) {
  return "module " + std::to_string(k) + " (" + rig.module(k).name + ")";
}

// "cameras 2,3" (left, right).
std::string Cameras(const StereoModule& m) {
  return "cameras " + std::to_string(m.left_camera) + "," + std::to_string(m.right_camera);
}

// The truth's module with `m`'s left and right cameras; -1 if none.
int TruthModuleOf(const StereoModule& m, const Rig& truth) {
  for (int j = 0; j < truth.num_modules(); ++j)
    if (truth.module(j).left_camera == m.left_camera && truth.module(j).right_camera == m.right_camera) return j;
  return -1;
}

}  // namespace

std::string TruthModuleMismatch(const Rig& calibrated, const Rig& truth) {
  if (truth.num_modules() != calibrated.num_modules() || truth.num_cameras() != calibrated.num_cameras())
    return "has " + std::to_string(truth.num_modules()) + " module(s) and " + std::to_string(truth.num_cameras()) +
           " camera(s), the rig has " + std::to_string(calibrated.num_modules()) + " and " +
           std::to_string(calibrated.num_cameras());
  for (int k = 0; k < calibrated.num_modules(); ++k) {
    const StereoModule& m = calibrated.module(k);
    if (TruthModuleOf(m, truth) >= 0) continue;
    for (int j = 0; j < truth.num_modules(); ++j) {
      const StereoModule& t = truth.module(j);
      if (t.left_camera == m.right_camera && t.right_camera == m.left_camera)
        return "the rig's " + ModuleName(calibrated, k) + " has left camera " + std::to_string(m.left_camera) +
               " and right camera " + std::to_string(m.right_camera) + ", the truth's " + ModuleName(truth, j) +
               " the same two the other way round (left " + std::to_string(t.left_camera) + ", right " +
               std::to_string(t.right_camera) + "): left and right swapped in the layout it was calibrated with?";
    }
    std::string truths;
    for (int j = 0; j < truth.num_modules(); ++j)
      truths += (j ? "; " : "") + ModuleName(truth, j) + " " + Cameras(truth.module(j));
    return "the rig's " + ModuleName(calibrated, k) + " uses " + Cameras(m) + " (left, right), which no module of " +
           "the truth does (" + truths + "): a rig of other cameras?";
  }
  return "";
}

Rig TruthInModuleOrderOf(const Rig& calibrated, const Rig& truth) {
  std::vector<int> order;  // the truth's module for each of calibrated's
  for (const StereoModule& m : calibrated.modules()) {
    order.push_back(TruthModuleOf(m, truth));
    STEREORIG_CHECK(order.back() >= 0);
  }
  std::vector<StereoModule> modules;
  std::vector<Pose> first_from_module;
  for (int j : order) {
    modules.push_back(truth.module(j));
    first_from_module.push_back(truth.S(order[0], j));
  }
  return Rig(truth.cameras(), truth.camera_names(), modules, first_from_module);
}

void TriangulateThroughModule(const Rig& truth, const Rig& calibrated, int k, const std::vector<Eigen::Vector3d>& p_ref,
                              std::vector<Eigen::Vector3d>* p_cal, std::vector<Eigen::Vector3d>* p_true,
                              std::vector<int>* used) {
  const StereoModule& tm = truth.module(k);
  const StereoModule& cm = calibrated.module(k);
  const Camera& tl = truth.camera(tm.left_camera);
  const Camera& tr = truth.camera(tm.right_camera);
  const Pose& module_from_ref = truth.S(k, 0);
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

double ModuleAgreementRms(const Rig& truth, const Rig& calibrated, const Pose& module_i_from_module_j, int i, int j,
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
    s2 += (it->second - module_i_from_module_j * cj[n]).squaredNorm();
    ++count;
  }
  return count ? std::sqrt(s2 / count) : NAN;
}

}  // namespace stereorig
