#include "calib/check/shared_lens_change.h"

#include <ceres/ceres.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "calib/check/board_pose.h"
#include "calib/check/camera_change.h"
#include "calib/core/lens_drift.h"

namespace stereorig {

std::string SharedLensChange::Describe() const {
  auto shown = [](double x, double step) { return std::abs(x) < step / 2 ? 0.0 : x; };  // no "-0.00"
  char text[240];
  std::snprintf(text, sizeof text,
                "every camera's lens changed alike: focal length %+.3f %%, principal point %+.2f, %+.2f px",
                shown(focal_percent, 0.001), shown(principal_point_px.x(), 0.01), shown(principal_point_px.y(), 0.01));
  std::string out = text;
  // The turn only where it shows at the precision printed: +0.01 px reads
  // as 0.0004 deg, and "turned alike by 0.000 deg" says nothing.
  const bool moved = shown(principal_point_px.x(), 0.01) != 0 || shown(principal_point_px.y(), 0.01) != 0;
  if (moved && shown(turn_equivalent_deg, 0.001) != 0) {
    std::snprintf(text, sizeof text, ", or every camera turned alike by %.3f deg, as which that shift reads",
                  turn_equivalent_deg);
    out += text;
  }
  return out;
}

namespace {

// One corner through its capture's board pose (rt, 6) and the shared lens
// change (s, dx, dy: DriftedPixel). Numeric: mrcal's projection is not
// templated.
struct SharedLensResidual {
  const Camera* camera;
  Pose cam_from_ref;
  Eigen::Vector3d p_front;
  Eigen::Vector2d q;
  bool operator()(const double* rt, const double* lens, double* residual) const {
    const Pose ref_from_front = Pose::FromRotationVector({rt[0], rt[1], rt[2]}, {rt[3], rt[4], rt[5]});
    return DriftedLensResidual(*camera, cam_from_ref * (ref_from_front * p_front), lens, q, residual);
  }
};

}  // namespace

SharedLensChange FitSharedLensChange(const Rig& rig, const Target& target,
                                     const std::map<int, std::vector<const BoardObservation*>>& by_capture,
                                     const std::map<int, Pose>& seed) {
  SharedLensChange change;
  double lens[3] = {0, 0, 0};
  std::map<int, std::array<double, 6>> poses;
  std::vector<Camera> cameras = rig.cameras();
  std::vector<Pose> cam_from_ref;
  for (int c = 0; c < rig.num_cameras(); ++c) cam_from_ref.push_back(rig.CamFromReference(c));
  ceres::Problem problem;
  for (const auto& [capture, views] : by_capture) {
    const auto s = seed.find(capture);
    if (s == seed.end()) continue;
    std::array<double, 6>& rt = poses[capture];
    const Eigen::Vector3d r = s->second.RotationVector(), t = s->second.translation_mm();
    rt = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
    for (const BoardObservation* v : views) {
      for (size_t k = 0; k < v->corner_ids.size(); ++k) {
        problem.AddResidualBlock(
            new ceres::NumericDiffCostFunction<SharedLensResidual, ceres::CENTRAL, 2, 6, 3>(
                new SharedLensResidual{&cameras[v->camera], cam_from_ref[v->camera],
                                       CornerInFront(target, v->face, v->corner_ids[k]), v->q_px[k]}),
            nullptr, rt.data(), lens);
        ++change.corners;
      }
    }
  }
  // Three unknowns shared, six per capture.
  if (change.corners * 2 < 3 + 6 * static_cast<int>(poses.size()) + 1) return change;
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return change;
  change.fitted = true;
  change.focal_percent = 100 * lens[0];
  change.principal_point_px = {lens[1], lens[2]};
  double fx = 0;
  for (const Camera& cam : cameras) fx += cam.fx() / cameras.size();
  change.turn_equivalent_deg = std::atan(change.principal_point_px.norm() / fx) * 180 / M_PI;
  return change;
}

Rig WithSharedLensChange(const Rig& rig, const SharedLensChange& change) {
  std::vector<Camera> cameras;
  for (const Camera& cam : rig.cameras())
    cameras.push_back(WithLensDrift(cam, {change.focal_percent, change.principal_point_px}));
  Rig changed(cameras, rig.camera_names(), rig.modules(), rig.S(), rig.Where());
  changed.provenance() = rig.provenance();
  return changed;
}

}  // namespace stereorig
