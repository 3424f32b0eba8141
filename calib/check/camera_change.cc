#include "calib/check/camera_change.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <limits>

#include "calib/check/board_pose.h"
#include "calib/core/lens_drift.h"

namespace stereorig {

const char* CameraChangeKindName(CameraChangeKind kind) {
  switch (kind) {
    case CameraChangeKind::kMoved:
      return "moved";
    case CameraChangeKind::kLens:
      return "lens";
    case CameraChangeKind::kMovedOrLens:
      return "moved_or_lens";
    case CameraChangeKind::kUnexplained:
      return "unexplained";
    case CameraChangeKind::kNotFitted:
      break;
  }
  return "not_fitted";
}

std::string CameraChange::Describe() const { return DescribeChange() + (role.empty() ? "" : " [" + role + "]"); }

std::string CameraChange::DescribeChange() const {
  // Printed as rounded: no "-0.00".
  auto shown = [](double x, double step) { return std::abs(x) < step / 2 ? 0.0 : x; };
  // "0.079 px with a new pose"; a pose fit whose solve failed has none.
  auto residual = [](double rms_px, const char* with) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3f px with a new %s", rms_px, with);
    return std::string(text);
  };
  std::string out = "camera " + std::to_string(camera);
  switch (kind) {
    case CameraChangeKind::kMoved: {
      // The pose fit's motion, so that the night's reader knows a knock
      // from a creep (0.1 to 3 degrees read to 0.001 degree on simulated
      // nights, docs/verify-and-check.md).
      char text[96];
      std::snprintf(text, sizeof text, " moved: turned %.3f deg, shifted %.3f mm", shown(turned_deg, 0.001),
                    shown(shifted_mm, 0.001));
      return out + text;
    }
    case CameraChangeKind::kLens: {
      char text[160];
      std::snprintf(text, sizeof text, "'s lens changed: focal length %+.3f %%, principal point %+.2f, %+.2f px",
                    shown(focal_percent, 0.001), shown(principal_point_px.x(), 0.01),
                    shown(principal_point_px.y(), 0.01));
      return out + text;
    }
    case CameraChangeKind::kMovedOrLens: {
      // Both fits' sizes: a knock of degrees reads otherwise as a drift of
      // hundredths (the sizes were in the JSON report alone).
      char text[200];
      std::snprintf(text, sizeof text,
                    " moved or its lens changed (either explains its corners): turned %.3f deg, shifted %.3f mm, or "
                    "focal length %+.3f %%, principal point %+.2f, %+.2f px",
                    shown(turned_deg, 0.001), shown(shifted_mm, 0.001), shown(focal_percent, 0.001),
                    shown(principal_point_px.x(), 0.01), shown(principal_point_px.y(), 0.01));
      return out + text;
    }
    case CameraChangeKind::kUnexplained: {
      out += " changed: neither a new pose nor a new lens alone explains its corners (";
      if (std::isfinite(moved_rms_px)) {
        out += "residual ";
        out += residual(moved_rms_px, "pose");
        out += ", ";
      } else {
        out += "the pose fit's solve failed, residual ";  // no "; ": it separates the explanation's items
      }
      out += residual(lens_rms_px, "lens");  // the lens fit is linear: always one
      char against[48];
      std::snprintf(against, sizeof against, ", against %.3f px)", threshold_px);
      return out + against;
    }
    case CameraChangeKind::kNotFitted:
      break;
  }
  char text[96];
  std::snprintf(text, sizeof text, " changed: too few corners (%d) to fit a new pose or a new lens", corners);
  return out + text;
}

namespace {

// A corner of the camera: its point in the reference frame (through the pose
// the other cameras imply) and where the camera saw it.
struct Corner {
  Eigen::Vector3d p_ref;
  Eigen::Vector2d q;
};

// Residual of one corner with the camera's pose refitted:
// Project(Pose(rt) * cam_from_ref * p_ref) - q, numerically differentiated
// (mrcal's projection is not templated).
struct MovedResidual {
  const Camera* camera;
  Pose cam_from_ref;
  Corner corner;
  bool operator()(const double* rt, double* residual) const {
    const Pose new_from_old = Pose::FromRotationVector({rt[0], rt[1], rt[2]}, {rt[3], rt[4], rt[5]});
    const Eigen::Vector3d p_cam = new_from_old * (cam_from_ref * corner.p_ref);
    if (p_cam.z() <= 0) return false;
    const Eigen::Vector2d e = camera->Project(p_cam) - corner.q;
    residual[0] = e.x();
    residual[1] = e.y();
    return true;
  }
  static ceres::CostFunction* Create(const Camera* camera, const Pose& cam_from_ref, const Corner& corner) {
    return new ceres::NumericDiffCostFunction<MovedResidual, ceres::CENTRAL, 2, 6>(
        new MovedResidual{camera, cam_from_ref, corner});
  }
};

// The pose fit's per-axis RMS; *new_from_old its motion (unset if the
// solve failed).
double MovedFitRms(const Camera& camera, const Pose& cam_from_ref, const std::vector<Corner>& corners,
                   Pose* new_from_old) {
  double rt[6] = {0, 0, 0, 0, 0, 0};
  ceres::Problem problem;
  for (const Corner& c : corners)
    problem.AddResidualBlock(MovedResidual::Create(&camera, cam_from_ref, c), nullptr, rt);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  // A solve that failed explains nothing (its final cost is not a cost).
  if (!summary.IsSolutionUsable()) return std::numeric_limits<double>::infinity();
  *new_from_old = Pose::FromRotationVector({rt[0], rt[1], rt[2]}, {rt[3], rt[4], rt[5]});
  return RmsPerAxis(2.0 * summary.final_cost, corners.size());
}

}  // namespace

double RmsPerAxis(double sum_of_squares, size_t corners) { return std::sqrt(sum_of_squares / (2.0 * corners)); }

bool DriftedLensResidual(const Camera& camera, const Eigen::Vector3d& p_cam, const double* lens,
                         const Eigen::Vector2d& q, double* residual) {
  if (p_cam.z() <= 0) return false;
  const Eigen::Vector2d e = DriftedPixel(camera, camera.Project(p_cam), lens[0], Eigen::Vector2d(lens[1], lens[2])) - q;
  residual[0] = e.x();
  residual[1] = e.y();
  return true;
}

std::string CameraRole(const Rig& rig, int camera) {
  for (int m = 0; m < rig.num_modules(); ++m) {
    if (rig.module(m).left_camera == camera) return "module " + std::to_string(m) + "'s left camera";
    if (rig.module(m).right_camera == camera) return "module " + std::to_string(m) + "'s right camera";
  }
  return "";
}

CameraChange ExplainCameraChange(const Rig& rig, const Target& target, int camera, const std::vector<PosedView>& views,
                                 double threshold_px) {
  const Camera& cam = rig.camera(camera);
  const Pose cam_from_ref = rig.CamFromReference(camera);
  std::vector<Corner> corners;
  for (const PosedView& pv : views)
    for (size_t k = 0; k < pv.view->corner_ids.size(); ++k)
      corners.push_back(
          {pv.ref_from_front * CornerInFront(target, pv.view->face, pv.view->corner_ids[k]), pv.view->q_px[k]});
  CameraChange change;
  change.camera = camera;
  change.role = CameraRole(rig, camera);
  change.threshold_px = threshold_px;
  change.turned_deg = change.shifted_mm = std::numeric_limits<double>::quiet_NaN();
  change.shift_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  change.corners = static_cast<int>(corners.size());
  if (change.corners < kMinCornersToFit) {  // no fit, not a perfect one (null in the report)
    change.kind = CameraChangeKind::kNotFitted;
    change.moved_rms_px = change.lens_rms_px = std::numeric_limits<double>::quiet_NaN();
    return change;
  }

  // The lens fit is linear: every mrcal model stereorig uses maps its
  // normalised (distorted) coordinates u to q = f u + c, so the lens with
  // its focal length scaled by (1 + s) and its centre moved by d sees
  // q' = c + d + (1 + s)(q - c). Least squares on (s, dx, dy).
  const Eigen::Vector2d c(cam.cx(), cam.cy());
  Eigen::MatrixXd a(2 * corners.size(), 3);
  Eigen::VectorXd b(2 * corners.size());
  for (size_t i = 0; i < corners.size(); ++i) {
    const Eigen::Vector3d p_cam = cam_from_ref * corners[i].p_ref;
    const Eigen::Vector2d q = cam.Project(p_cam);
    // q' - q_observed = (q - q_observed) + s (q - c) + d
    a.row(2 * i) << q.x() - c.x(), 1, 0;
    a.row(2 * i + 1) << q.y() - c.y(), 0, 1;
    b.segment<2>(2 * i) = corners[i].q - q;
  }
  const Eigen::Vector3d x = a.colPivHouseholderQr().solve(b);
  change.focal_percent = 100.0 * x[0];
  change.principal_point_px = x.tail<2>();
  change.lens_rms_px = RmsPerAxis((a * x - b).squaredNorm(), corners.size());
  Pose new_from_old;
  change.moved_rms_px = MovedFitRms(cam, cam_from_ref, corners, &new_from_old);
  if (std::isfinite(change.moved_rms_px)) {
    change.turned_deg = AngleBetweenDeg(new_from_old, Pose::Identity());
    // The camera centre's move, in the reference frame.
    change.shift_mm =
        (new_from_old * cam_from_ref).Inverse().translation_mm() - cam_from_ref.Inverse().translation_mm();
    change.shifted_mm = change.shift_mm.norm();
  }

  const bool moved_fits = change.moved_rms_px <= threshold_px, lens_fits = change.lens_rms_px <= threshold_px;
  change.kind = moved_fits && lens_fits ? CameraChangeKind::kMovedOrLens
                : moved_fits            ? CameraChangeKind::kMoved
                : lens_fits             ? CameraChangeKind::kLens
                                        : CameraChangeKind::kUnexplained;
  return change;
}

}  // namespace stereorig
