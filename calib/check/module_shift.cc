#include "calib/check/module_shift.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "calib/check/board_pose.h"

namespace stereorig {

namespace {

// One corner of the module's camera through the module shifted by t (the
// camera's centre moves by t, its orientation kept: cam_from_ref (p - t))
// and its lens changed by (s, dx, dy) (DriftedPixel, as camera_change.cc's
// lens fit). Numeric: mrcal's projection is not templated.
struct ShiftedResidual {
  const Camera* camera;
  Pose cam_from_ref;
  Eigen::Vector3d p_ref;
  Eigen::Vector2d q;
  bool operator()(const double* t, const double* lens, double* residual) const {
    return DriftedLensResidual(*camera, cam_from_ref * (p_ref - Eigen::Vector3d(t[0], t[1], t[2])), lens, q, residual);
  }
};

// The same corner with the camera turned about its own centre (rotation
// vector r) instead of its lens changed, the module's shift t held: a
// principal point's shift reads, to first order, as such a turn.
struct TurnedResidual {
  ShiftedResidual shifted;
  Eigen::Vector3d t;
  bool operator()(const double* r, double* residual) const {
    const Pose turned = Pose::FromRotationVector({r[0], r[1], r[2]}, Eigen::Vector3d::Zero());
    const Eigen::Vector3d p_cam = turned * (shifted.cam_from_ref * (shifted.p_ref - t));
    if (p_cam.z() <= 0) return false;
    const Eigen::Vector2d e = shifted.camera->Project(p_cam) - shifted.q;
    residual[0] = e.x();
    residual[1] = e.y();
    return true;
  }
};

// The turn alone that best fits `corners` at the shift t: its per-axis RMS
// (+inf when the solve fails), *turned_deg its size.
double TurnedFitRms(const std::vector<ShiftedResidual>& corners, const double* t, double* turned_deg) {
  double r[3] = {0, 0, 0};
  ceres::Problem problem;
  for (const ShiftedResidual& c : corners)
    problem.AddResidualBlock(new ceres::NumericDiffCostFunction<TurnedResidual, ceres::CENTRAL, 2, 3>(
                                 new TurnedResidual{c, Eigen::Vector3d(t[0], t[1], t[2])}),
                             nullptr, r);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return std::numeric_limits<double>::infinity();
  *turned_deg = Eigen::Vector3d(r[0], r[1], r[2]).norm() * 180 / M_PI;
  return RmsPerAxis(2.0 * summary.final_cost, corners.size());
}

}  // namespace

ModuleShift ExplainModuleShift(const Rig& rig, const Target& target, const std::vector<ModuleCameraViews>& cameras) {
  ModuleShift out;
  double t[3] = {0, 0, 0};
  std::vector<std::array<double, 3>> lens(cameras.size(), {0, 0, 0});
  std::vector<std::vector<ShiftedResidual>> corners(cameras.size());
  ceres::Problem problem;
  for (size_t k = 0; k < cameras.size(); ++k) {
    const Camera& cam = rig.camera(cameras[k].camera);
    const Pose cam_from_ref = rig.CamFromReference(cameras[k].camera);
    for (const PosedView& pv : cameras[k].views)
      for (size_t i = 0; i < pv.view->corner_ids.size(); ++i)
        corners[k].push_back({&cam, cam_from_ref,
                              pv.ref_from_front * CornerInFront(target, pv.view->face, pv.view->corner_ids[i]),
                              pv.view->q_px[i]});
    if (static_cast<int>(corners[k].size()) < kMinCornersToFit) return out;
    for (const ShiftedResidual& r : corners[k])
      problem.AddResidualBlock(
          new ceres::NumericDiffCostFunction<ShiftedResidual, ceres::CENTRAL, 2, 3, 3>(new ShiftedResidual(r)), nullptr,
          t, lens[k].data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  // Each camera's per-axis RMS with lens `l` at the shift t.
  auto rms = [&](size_t k, const double* l) {
    double ss = 0;
    for (const ShiftedResidual& r : corners[k]) {
      double e[2];
      if (!r(t, l, e)) return std::numeric_limits<double>::infinity();
      ss += e[0] * e[0] + e[1] * e[1];
    }
    return RmsPerAxis(ss, corners[k].size());
  };
  // First the lenses alone (no shift): where they explain every camera, no
  // shift is needed, and the cameras are named one by one.
  problem.SetParameterBlockConstant(t);
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return out;
  for (size_t k = 0; k < cameras.size(); ++k)
    out.shift_needed = out.shift_needed || !(rms(k, lens[k].data()) <= cameras[k].threshold_px);
  problem.SetParameterBlockVariable(t);
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return out;
  auto all_within = [&] {
    for (size_t k = 0; k < cameras.size(); ++k)
      if (!(rms(k, lens[k].data()) <= cameras[k].threshold_px)) return false;
    return true;
  };
  out.explains = all_within();
  if (!out.explains) return out;
  // Each camera's lens held as stored where the shift (refitted) and the
  // other lens still explain every camera: a camera the shift alone
  // explains is not named. Refitted, not read at the joint fit's shift: a
  // shift along the cameras' axes trades with both focal lengths, and
  // camera 1, unchanged, read a lens change of +0.017 % there, over its
  // threshold, with the shift 0.516 mm for 0.5.
  // The cameras the shift alone most nearly explains are tried first.
  std::vector<std::pair<double, size_t>> order;
  const double stored[3] = {0, 0, 0};
  for (size_t k = 0; k < cameras.size(); ++k) order.push_back({rms(k, stored) / cameras[k].threshold_px, k});
  std::sort(order.begin(), order.end());
  std::vector<bool> held(cameras.size(), false);
  for (const auto& [ratio, k] : order) {
    const double t_before[3] = {t[0], t[1], t[2]};
    const std::vector<std::array<double, 3>> lens_before = lens;
    lens[k] = {0, 0, 0};
    problem.SetParameterBlockConstant(lens[k].data());
    ceres::Solve(options, &problem, &summary);
    if (summary.IsSolutionUsable() && all_within()) {
      held[k] = true;
      continue;
    }
    problem.SetParameterBlockVariable(lens[k].data());
    std::copy(t_before, t_before + 3, t);
    lens = lens_before;
  }
  out.shift_mm = Eigen::Vector3d(t[0], t[1], t[2]);
  for (size_t k = 0; k < cameras.size(); ++k) {
    if (held[k]) continue;  // the shift alone explains it
    const double with_lens = rms(k, lens[k].data());
    CameraChange change;
    change.camera = cameras[k].camera;
    change.corners = static_cast<int>(corners[k].size());
    change.lens_rms_px = with_lens;
    change.threshold_px = cameras[k].threshold_px;
    change.focal_percent = 100 * lens[k][0];
    change.principal_point_px = {lens[k][1], lens[k][2]};
    // Or a turn of its own, about its centre (its shift is the module's).
    change.moved_rms_px = TurnedFitRms(corners[k], t, &change.turned_deg);
    change.kind = change.moved_rms_px <= change.threshold_px ? CameraChangeKind::kMovedOrLens : CameraChangeKind::kLens;
    change.shifted_mm = 0;
    change.shift_mm = Eigen::Vector3d::Zero();
    if (!std::isfinite(change.moved_rms_px)) {
      change.turned_deg = change.shifted_mm = std::numeric_limits<double>::quiet_NaN();
      change.shift_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
    change.role = CameraRole(rig, change.camera);
    out.lenses.push_back(change);
  }
  return out;
}

}  // namespace stereorig
