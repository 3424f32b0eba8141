#include "calib/check/board_pose.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <opencv2/calib3d.hpp>
#include <utility>

namespace stereorig {

Eigen::Vector3d CornerInFront(const Target& target, Face face, int id) {
  const Eigen::Vector3d p = target.CornerInFace(id);
  return face == Face::kFront ? p : target.back_from_front().Inverse() * p;
}

namespace {

// R(r) of a rotation vector r (rad), and d R / d r_k for k = 0, 1, 2: each
// unit vector turned by Ceres' AngleAxisRotatePoint on Jets. Once per pose
// and evaluation, not per corner.
struct TurnAndDerivative {
  Eigen::Matrix3d r;
  Eigen::Matrix3d dr[3];
};

TurnAndDerivative Turn(const double* r_rad) {
  using Jet3 = ceres::Jet<double, 3>;
  const Jet3 r[3] = {Jet3(r_rad[0], 0), Jet3(r_rad[1], 1), Jet3(r_rad[2], 2)};
  TurnAndDerivative turn;
  for (int j = 0; j < 3; ++j) {
    const Jet3 unit[3] = {Jet3(j == 0 ? 1.0 : 0.0), Jet3(j == 1 ? 1.0 : 0.0), Jet3(j == 2 ? 1.0 : 0.0)};
    Jet3 column[3];
    ceres::AngleAxisRotatePoint(r, unit, column);
    for (int i = 0; i < 3; ++i) {
      turn.r(i, j) = column[i].a;
      for (int k = 0; k < 3; ++k) turn.dr[k](i, j) = column[i].v[k];
    }
  }
  return turn;
}

// ProjectBoardCorner with the pose's turn made already.
bool ProjectTurnedCorner(const Camera& camera, const Pose& cam_from_ref, const TurnAndDerivative& turn,
                         const double* t_mm, const Eigen::Vector3d& p_front, Eigen::Vector2d* q,
                         Eigen::Matrix<double, 2, 6>* dq_drt) {
  const Eigen::Vector3d p_ref = turn.r * p_front + Eigen::Vector3d(t_mm[0], t_mm[1], t_mm[2]);
  const Eigen::Vector3d p_cam = cam_from_ref * p_ref;
  if (p_cam.z() <= 0) return false;
  if (!dq_drt) {
    *q = camera.Project(p_cam);
    return true;
  }
  Eigen::Matrix<double, 2, 3> dq_dp_cam;
  *q = camera.Project(p_cam, &dq_dp_cam);
  Eigen::Matrix3d dp_ref_dr;
  for (int k = 0; k < 3; ++k) dp_ref_dr.col(k) = turn.dr[k] * p_front;
  const Eigen::Matrix<double, 2, 3> dq_dp_ref = dq_dp_cam * cam_from_ref.rotation();
  dq_drt->leftCols<3>() = dq_dp_ref * dp_ref_dr;
  dq_drt->rightCols<3>() = dq_dp_ref;
  return true;
}

}  // namespace

bool ProjectBoardCorner(const Camera& camera, const Pose& cam_from_ref, const double* rt,
                        const Eigen::Vector3d& p_front, Eigen::Vector2d* q, Eigen::Matrix<double, 2, 6>* dq_drt) {
  return ProjectTurnedCorner(camera, cam_from_ref, Turn(rt), rt + 3, p_front, q, dq_drt);
}

namespace {

// Residuals of one view's corners: their projections (ProjectBoardCorner)
// minus where they were seen, x and y of each in turn. One block a view, so
// the pose's turn is made once an evaluation.
class ViewResidual : public ceres::CostFunction {
 public:
  ViewResidual(const Camera* camera, const Pose& cam_from_ref, std::vector<Eigen::Vector3d> p_front,
               std::vector<Eigen::Vector2d> q)
      : camera_(camera), cam_from_ref_(cam_from_ref), p_front_(std::move(p_front)), q_(std::move(q)) {
    set_num_residuals(static_cast<int>(2 * p_front_.size()));
    mutable_parameter_block_sizes()->push_back(6);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* rt = parameters[0];
    const TurnAndDerivative turn = Turn(rt);
    const bool want_jacobian = jacobians && jacobians[0];
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> jacobian(
        want_jacobian ? jacobians[0] : nullptr, want_jacobian ? num_residuals() : 0, 6);
    for (size_t k = 0; k < p_front_.size(); ++k) {
      Eigen::Vector2d q;
      Eigen::Matrix<double, 2, 6> dq_drt;
      if (!ProjectTurnedCorner(*camera_, cam_from_ref_, turn, rt + 3, p_front_[k], &q,
                               want_jacobian ? &dq_drt : nullptr))
        return false;
      residuals[2 * k] = q.x() - q_[k].x();
      residuals[2 * k + 1] = q.y() - q_[k].y();
      if (want_jacobian) jacobian.middleRows<2>(static_cast<Eigen::Index>(2 * k)) = dq_drt;
    }
    return true;
  }

 private:
  const Camera* camera_;
  Pose cam_from_ref_;
  std::vector<Eigen::Vector3d> p_front_;
  std::vector<Eigen::Vector2d> q_;
};

bool SeedWithPnp(const Rig& rig, const Target& target, const BoardObservation& view, Pose* ref_from_front) {
  if (view.corner_ids.size() < 6) return false;
  const Camera& cam = rig.camera(view.camera);
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> normalized;
  for (size_t k = 0; k < view.corner_ids.size(); ++k) {
    Eigen::Vector3d v;
    if (!cam.Unproject(view.q_px[k], &v) || v.z() <= 0) continue;
    const Eigen::Vector3d p = target.CornerInFace(view.corner_ids[k]);
    object.emplace_back(p.x(), p.y(), p.z());
    normalized.emplace_back(v.x() / v.z(), v.y() / v.z());
  }
  if (object.size() < 6) return false;
  cv::Mat rvec, tvec;
  // Normalised image coordinates: identity camera matrix, no distortion (the
  // lens was removed by mrcal's unprojection).
  if (!cv::solvePnP(object, normalized, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) {
    return false;
  }
  const Pose cam_from_face = Pose::FromRotationVector({rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)},
                                                      {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)});
  const Pose face_from_front = view.face == Face::kFront ? Pose::Identity() : target.back_from_front();
  *ref_from_front = rig.CamFromReference(view.camera).Inverse() * cam_from_face * face_from_front;
  return true;
}

// d q / d (r, t) of ref_from_front for one corner seen by `camera`. (2x6;
// zero behind the camera, where the corner is not seen)
Eigen::Matrix<double, 2, 6> PoseJacobian(const Camera& camera, const Pose& cam_from_ref, const Pose& ref_from_front,
                                         const Eigen::Vector3d& p_front) {
  const Eigen::Vector3d r = ref_from_front.RotationVector();
  const Eigen::Vector3d t = ref_from_front.translation_mm();
  const double rt[6] = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
  Eigen::Vector2d q;
  Eigen::Matrix<double, 2, 6> j = Eigen::Matrix<double, 2, 6>::Zero();
  ProjectBoardCorner(camera, cam_from_ref, rt, p_front, &q, &j);
  return j;
}

}  // namespace

Eigen::Matrix<double, 6, 6> BoardPoseCovariance(const Rig& rig, const Target& target,
                                                const std::vector<const BoardObservation*>& pose_views,
                                                const std::vector<double>& sigma_px, const Pose& ref_from_front) {
  // Information of the pose from the views it came from, each corner
  // weighted by its camera's noise.
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  for (const BoardObservation* v : pose_views) {
    const Camera& cam = rig.camera(v->camera);
    const Pose cam_from_ref = rig.CamFromReference(v->camera);
    const double w = 1.0 / (sigma_px[v->camera] * sigma_px[v->camera]);
    for (int id : v->corner_ids) {
      const auto j = PoseJacobian(cam, cam_from_ref, ref_from_front, CornerInFront(target, v->face, id));
      information += w * j.transpose() * j;
    }
  }
  return information.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());
}

PredictionStatistics PredictionErrorStatistics(const Rig& rig, const Target& target,
                                               const std::vector<const BoardObservation*>& pose_views,
                                               const std::vector<std::vector<double>>& sigma_px_sources,
                                               const BoardObservation& view, const Pose& ref_from_front) {
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  for (const std::vector<double>& sigma_px : sigma_px_sources)
    covariance += BoardPoseCovariance(rig, target, pose_views, sigma_px, ref_from_front);
  const Camera& cam = rig.camera(view.camera);
  const Pose cam_from_ref = rig.CamFromReference(view.camera);
  Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
  for (int id : view.corner_ids) {
    const auto j = PoseJacobian(cam, cam_from_ref, ref_from_front, CornerInFront(target, view.face, id));
    a += j.transpose() * j;
  }
  const Eigen::Matrix<double, 6, 6> a_sigma = a * covariance;
  return {a_sigma.trace(), 2.0 * (a_sigma * a_sigma).trace()};
}

PredictionStatistics ViewPredictionStatistics(int num_corners, double noise_px, const PredictionStatistics& pose) {
  const double s2 = noise_px * noise_px, m = 2.0 * num_corners;
  return {m * s2 + pose.mean_ss_px2, 2 * m * s2 * s2 + 4 * s2 * pose.mean_ss_px2 + pose.var_ss_px4};
}

std::vector<Eigen::Vector2d> ReprojectionErrors(const Rig& rig, const Target& target, const BoardObservation& view,
                                                const Pose& ref_from_front) {
  const Camera& cam = rig.camera(view.camera);
  const Pose cam_from_front = rig.CamFromReference(view.camera) * ref_from_front;
  std::vector<Eigen::Vector2d> e;
  for (size_t k = 0; k < view.corner_ids.size(); ++k) {
    e.push_back(cam.Project(cam_from_front * CornerInFront(target, view.face, view.corner_ids[k])) - view.q_px[k]);
  }
  return e;
}

BoardPoseEstimate EstimateBoardPose(const Rig& rig, const Target& target,
                                    const std::vector<const BoardObservation*>& views, const Pose* seed_pose) {
  BoardPoseEstimate out;
  if (seed_pose) {
    out.ref_from_front = *seed_pose;
  } else {
    const BoardObservation* seed = nullptr;
    for (const BoardObservation* v : views)
      if (!seed || v->corner_ids.size() > seed->corner_ids.size()) seed = v;
    if (!seed || !SeedWithPnp(rig, target, *seed, &out.ref_from_front)) return out;
  }

  const Eigen::Vector3d r0 = out.ref_from_front.RotationVector();
  const Eigen::Vector3d t0 = out.ref_from_front.translation_mm();
  double rt[6] = {r0.x(), r0.y(), r0.z(), t0.x(), t0.y(), t0.z()};
  ceres::Problem problem;
  for (const BoardObservation* v : views) {
    if (v->corner_ids.empty()) continue;
    std::vector<Eigen::Vector3d> p_front;
    for (int id : v->corner_ids) p_front.push_back(CornerInFront(target, v->face, id));
    problem.AddResidualBlock(
        new ViewResidual(&rig.camera(v->camera), rig.CamFromReference(v->camera), std::move(p_front), v->q_px), nullptr,
        rt);
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  // A pose from one camera has a flat direction (depth against tilt); stop
  // on parameters, not on a relative cost change, or it stops short there.
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return out;
  out.ref_from_front = Pose::FromRotationVector({rt[0], rt[1], rt[2]}, {rt[3], rt[4], rt[5]});
  double ss = 0;
  for (const BoardObservation* v : views)
    for (const Eigen::Vector2d& e : ReprojectionErrors(rig, target, *v, out.ref_from_front)) {
      ss += e.squaredNorm();
      ++out.num_corners;
    }
  // Per-axis RMS, as mrcal reports it.
  out.rms_px = std::sqrt(ss / (2.0 * std::max(1, out.num_corners)));
  out.ok = true;
  return out;
}

}  // namespace stereorig
