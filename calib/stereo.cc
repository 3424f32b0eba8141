#include "calib/stereo.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "calib/core/input_error.h"
#include "calib/projection_uncertainty.h"

namespace stereorig {

void StereoOptions::Check() const {
  if (min_shared_views < 1) throw InputError("options.min_shared_views", "must be >= 1");
}

Pose AveragePoses(const std::vector<Pose>& poses) {
  STEREORIG_CHECK(!poses.empty());
  const Eigen::Quaterniond q0 = poses[0].quaternion();
  Eigen::Vector4d acc = Eigen::Vector4d::Zero();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (const Pose& p : poses) {
    Eigen::Quaterniond q = p.quaternion();
    if (q.dot(q0) < 0) q.coeffs() = -q.coeffs();
    acc += q.coeffs();
    t += p.translation_mm();
  }
  Eigen::Quaterniond mean;
  mean.coeffs() = acc.normalized();
  return Pose(mean, t / poses.size());
}

std::vector<double> RectifiedRowErrors(const Camera& left, const Camera& right, const Pose& right_from_left,
                                       const std::vector<Eigen::Vector2d>& q_left,
                                       const std::vector<Eigen::Vector2d>& q_right) {
  const Pose left_from_right = right_from_left.Inverse();
  const Eigen::Vector3d& baseline = left_from_right.translation_mm();  // right camera centre, left frame
  const Eigen::Vector3d ex = baseline.normalized();
  const Eigen::Vector3d z_mean = (Eigen::Vector3d::UnitZ() + left_from_right.rotation().col(2)).normalized();
  const Eigen::Vector3d ey = z_mean.cross(ex).normalized();
  const Eigen::Vector3d ez = ex.cross(ey);
  Eigen::Matrix3d rect_from_left;
  rect_from_left << ex.transpose(), ey.transpose(), ez.transpose();
  const double f = 0.5 * (left.fy() + right.fy());
  std::vector<double> out;
  for (size_t i = 0; i < q_left.size(); ++i) {
    Eigen::Vector3d vl, vr;
    if (!left.Unproject(q_left[i], &vl) || !right.Unproject(q_right[i], &vr)) continue;
    const Eigen::Vector3d al = rect_from_left * vl;
    const Eigen::Vector3d ar = rect_from_left * (left_from_right.rotation() * vr);
    out.push_back(f * (al.y() / al.z() - ar.y() / ar.z()));
  }
  return out;
}

StereoResult CalibrateStereo(int module, const ModuleLayout& layout, const IntrinsicsResult& left,
                             const IntrinsicsResult& right, const std::vector<const BoardObservation*>& left_views,
                             const std::vector<const BoardObservation*>& right_views, const CalibrationInput& input,
                             const StereoOptions& options, const IntrinsicsOptions& iopt) {
  const std::string where = input.source + ": module " + std::to_string(module) + " (" + layout.name + ")";
  const TargetGeometry& target = input.target;
  // Stage-1 views by capture.
  // Captures whose two views show different faces are set aside, both views:
  // one board pose per capture (mrcal's frame) cannot hold two faces without
  // back_from_front, which the joint solve does not model; and a face misread
  // by the detector looks the same. Stage 1 has used the views as they are.
  // Judged over every view, those stage 1 dropped too (CapturesWithDifferentFaces
  // says why); stage 3 takes this list from the report, it does not judge again.
  const std::vector<int> different_faces = CapturesWithDifferentFaces(input, layout.left_camera, layout.right_camera);
  const std::set<int> set_aside(different_faces.begin(), different_faces.end());
  std::map<int, int> left_view, right_view;
  for (size_t k = 0; k < left.captures.size(); ++k)
    if (!set_aside.count(left.captures[k])) left_view[left.captures[k]] = static_cast<int>(k);
  for (size_t k = 0; k < right.captures.size(); ++k)
    if (!set_aside.count(right.captures[k])) right_view[right.captures[k]] = static_cast<int>(k);
  std::vector<Pose> rl;
  for (const auto& [capture, kl] : left_view) {
    auto it = right_view.find(capture);
    if (it == right_view.end()) continue;
    STEREORIG_CHECK(left.faces[kl] == right.faces[it->second]);
    rl.push_back(right.cam_from_face[it->second] * left.cam_from_face[kl].Inverse());
  }
  if (static_cast<int>(rl.size()) < options.min_shared_views) {
    std::string aside;
    if (!set_aside.empty()) {
      aside = " (" + std::to_string(set_aside.size()) + " more set aside: their two cameras saw different faces)";
    }
    throw InputError(where, "too few views shared by both cameras: " + std::to_string(rl.size()) + ", need " +
                                std::to_string(options.min_shared_views) + aside);
  }
  const Pose right_from_left_seed = AveragePoses(rl);

  // The joint problem: camera 0 = left (reference), camera 1 = right.
  StereoResult result{left.camera, right.camera, {}, {}, {}, {}, {}, {}};
  std::map<int, const BoardObservation*> lobs, robs;
  for (const BoardObservation* o : left_views) lobs[o->capture] = o;
  for (const BoardObservation* o : right_views) robs[o->capture] = o;
  const int n = target.num_corners();
  // Views (capture, camera 0 left / 1 right) left out of the joint solve:
  // those whose inlier corners no longer fix a board pose (below).
  std::set<std::pair<int, int>> left_out;
  auto seen = [&](int capture, int cam) {
    return (cam == 0 ? left_view : right_view).count(capture) && !left_out.count({capture, cam});
  };
  MrcalProblem p;
  int missing = 0, non_positive = 0;
  // Solves from stage 1's intrinsics and board poses, every view but those
  // left out.
  auto solve = [&] {
    p = BoardProblem(iopt.lensmodel, target, 2);
    p.intrinsics = left.camera.intrinsics();
    p.intrinsics.insert(p.intrinsics.end(), right.camera.intrinsics().begin(), right.camera.intrinsics().end());
    p.imagersizes = {left.camera.imager_width_px(), left.camera.imager_height_px(), right.camera.imager_width_px(),
                     right.camera.imager_height_px()};
    p.extrinsics_fromref = {MrcalProblem::ToMrcal(right_from_left_seed)};
    result.captures.clear();
    result.faces.clear();
    std::set<int> captures;
    for (const auto& kv : left_view)
      if (seen(kv.first, 0)) captures.insert(kv.first);
    for (const auto& kv : right_view)
      if (seen(kv.first, 1)) captures.insert(kv.first);
    for (int capture : captures) {
      const int iframe = p.num_frames();
      const bool by_left = seen(capture, 0);
      const Pose left_from_face = by_left
                                      ? left.cam_from_face[left_view.at(capture)]
                                      : right_from_left_seed.Inverse() * right.cam_from_face[right_view.at(capture)];
      p.frames_toref.push_back(MrcalProblem::ToMrcal(left_from_face));
      result.captures.push_back(capture);
      result.faces.push_back(by_left ? left.faces[left_view.at(capture)] : right.faces[right_view.at(capture)]);
      for (int cam = 0; cam < 2; ++cam) {
        if (!seen(capture, cam)) continue;
        const BoardObservation* o = (cam == 0 ? lobs : robs).at(capture);
        p.observations.push_back({.icam = {.intrinsics = cam, .extrinsics = cam - 1}, .iframe = iframe});
        p.pool.resize(p.pool.size() + n);
        FillPoolBlock(*o, target, &p.pool[p.pool.size() - n]);
      }
    }
    missing = p.CountNonPositiveWeights();
    p.SelectPosesOnly();
    p.Optimize(options.verbose);
    p.selections.do_optimize_intrinsics_core = true;
    p.selections.do_optimize_intrinsics_distortions = true;
    non_positive = SolveFinal(&p, options.verbose);
  };
  solve();
  // A view whose inlier corners no longer fix its board pose (outlier
  // rejection left fewer than min_corners_per_view, or one row or column)
  // is left out and the rest solved again, as stage 1 does: a capture whose
  // left and right images were swapped had every corner of both its views
  // rejected, its board pose undetermined, J'J singular, and the module's
  // sigmas printed as 0 (baseline 89.9957 +- 0.0000 mm).
  for (;;) {
    std::vector<std::pair<int, int>> undetermined;
    for (int o = 0; o < p.num_observations(); ++o) {
      std::vector<int> inliers;
      for (int i = 0; i < n; ++i)
        if (p.pool[o * n + i].z > 0) inliers.push_back(i);
      if (static_cast<int>(inliers.size()) < iopt.min_corners_per_view || !CornersSpanAPlane(inliers, target.corners_x))
        undetermined.push_back({result.captures[p.observations[o].iframe], p.observations[o].icam.intrinsics});
    }
    if (undetermined.empty()) break;
    left_out.insert(undetermined.begin(), undetermined.end());
    int shared = 0;
    for (const auto& kv : left_view) shared += seen(kv.first, 0) && seen(kv.first, 1);
    if (shared < options.min_shared_views)
      throw InputError(where, "too few views shared by both cameras after outlier rejection: " +
                                  std::to_string(shared) + ", need " + std::to_string(options.min_shared_views));
    solve();
  }
  for (const auto& [capture, cam] : left_out) {
    result.report.views_left_out.push_back({capture, cam == 0 ? layout.left_camera : layout.right_camera});
    const std::map<int, int>& views = cam == 0 ? left_view : right_view;
    const IntrinsicsResult& stage1 = cam == 0 ? left : right;
    const auto view = views.find(capture);
    result.report.views_left_out_tilt_deg.push_back(view == views.end() ? std::numeric_limits<double>::quiet_NaN()
                                                                        : TiltDeg(stage1.cam_from_face[view->second]));
  }

  const int np = p.num_params();
  result.left = Camera(iopt.lensmodel, std::vector<double>(p.intrinsics.begin(), p.intrinsics.begin() + np),
                       left.camera.imager_width_px(), left.camera.imager_height_px(), where);
  result.right = Camera(iopt.lensmodel, std::vector<double>(p.intrinsics.begin() + np, p.intrinsics.end()),
                        right.camera.imager_width_px(), right.camera.imager_height_px(), where);
  result.right_from_left = MrcalProblem::FromMrcal(p.extrinsics_fromref[0]);
  for (const mrcal_pose_t& f : p.frames_toref) result.left_from_face.push_back(MrcalProblem::FromMrcal(f));

  StereoReport& r = result.report;
  r.module = module;
  r.module_name = layout.name;
  r.num_shared_views = 0;
  for (const auto& kv : left_view) r.num_shared_views += seen(kv.first, 0) && seen(kv.first, 1);
  r.different_face_captures = different_faces;
  r.num_frames = p.num_frames();
  const std::vector<double> x = p.Residuals();
  r.rms_px = BoardResidualRms(p, x);
  r.num_outliers = non_positive - missing;
  r.baseline_mm = result.right_from_left.DistanceMm();
  r.rotation_deg = result.right_from_left.AngleDeg();
  r.right_from_left_rotation_vector_deg = result.right_from_left.RotationVector() * 180.0 / M_PI;
  r.right_from_left_translation_mm = result.right_from_left.translation_mm();
  {
    // right_from_left is mrcal's rt_cam_ref of the right camera (extrinsics 0).
    const ProjectionUncertaintyEvaluator eval(p);
    r.covariance_status = eval.ok() ? "ok" : eval.message();
    if (!eval.ok()) {
      // Not a number, not 0: a 0 read as an exact baseline ("89.9957 +-
      // 0.0000 mm"); the report writes null, the summary "no sigma".
      const double none = std::numeric_limits<double>::quiet_NaN();
      r.baseline_sigma_mm = r.rotation_sigma_deg = none;
      r.right_from_left_rotation_vector_sigma_deg.setConstant(none);
      r.right_from_left_translation_sigma_mm.setConstant(none);
    } else {
      const Eigen::Matrix<double, 6, 6> cov = eval.ExtrinsicsCovariance(0);
      const Eigen::Vector3d rv(p.extrinsics_fromref[0].r.x, p.extrinsics_fromref[0].r.y, p.extrinsics_fromref[0].r.z);
      const Eigen::Vector3d t = r.right_from_left_translation_mm;
      const double deg = 180.0 / M_PI;
      for (int i = 0; i < 3; ++i) {
        r.right_from_left_rotation_vector_sigma_deg(i) = std::sqrt(cov(i, i)) * deg;
        r.right_from_left_translation_sigma_mm(i) = std::sqrt(cov(3 + i, 3 + i));
      }
      // The baseline |t| and the angle |r|, through their gradients t/|t| and r/|r|.
      const Eigen::Vector3d gt = t.normalized(), gr = rv.normalized();
      r.baseline_sigma_mm = std::sqrt(gt.dot(cov.block<3, 3>(3, 3) * gt));
      r.rotation_sigma_deg = std::sqrt(gr.dot(cov.block<3, 3>(0, 0) * gr)) * deg;
      const Eigen::MatrixXd joint = eval.JointIntrinsicsCovariance({0, 1}, /*regularisation_as_prior=*/true);
      for (int i = 0; i < np; ++i)
        for (int j = 0; j < np; ++j) r.intrinsics_cross_covariance.push_back(joint(i, np + j));
    }
  }

  // Corners both cameras saw (inliers in both), for the rectified-row error.
  std::vector<Eigen::Vector2d> ql, qr;
  for (int o = 0; o + 1 < p.num_observations(); ++o) {
    if (p.observations[o].iframe != p.observations[o + 1].iframe) continue;
    for (int i = 0; i < n; ++i) {
      const mrcal_point3_t& a = p.pool[o * n + i];
      const mrcal_point3_t& b = p.pool[(o + 1) * n + i];
      if (a.z <= 0 || b.z <= 0) continue;
      ql.emplace_back(a.x, a.y);
      qr.emplace_back(b.x, b.y);
    }
  }
  const std::vector<double> rows = RectifiedRowErrors(result.left, result.right, result.right_from_left, ql, qr);
  double s2 = 0, mx = 0;
  for (double d : rows) {
    s2 += d * d;
    mx = std::max(mx, std::abs(d));
  }
  r.num_corner_pairs = static_cast<int>(rows.size());
  r.rectified_row_rms_px = rows.empty() ? 0.0 : std::sqrt(s2 / rows.size());
  r.rectified_row_max_px = mx;

  for (int cam = 0; cam < 2; ++cam) {
    IntrinsicsReport& cr = cam == 0 ? r.left : r.right;
    const IntrinsicsResult& stage1 = cam == 0 ? left : right;
    cr.camera = stage1.report.camera;
    cr.camera_name = stage1.report.camera_name;
    cr.lensmodel = iopt.lensmodel;
    std::vector<ViewResidual> per_view = ViewResiduals(p, x, result.captures, cam);
    cr.num_views = static_cast<int>(per_view.size());
    double sum2 = 0;
    int count = 0;
    for (const ViewResidual& v : per_view) {
      sum2 += v.rms_px * v.rms_px * v.num_corners;  // per-coordinate mean square x corners
      count += v.num_corners;
    }
    cr.num_corners = count;
    cr.rms_px = count ? std::sqrt(sum2 / count) : 0.0;
    std::sort(per_view.begin(), per_view.end(), [](const auto& a, const auto& b) { return a.rms_px > b.rms_px; });
    per_view.resize(std::min<size_t>(per_view.size(), iopt.worst_views_reported));
    cr.worst_views = per_view;
    FillCoverageAndUncertainty(p, cam, iopt, stage1.camera.imager_width_px(), stage1.camera.imager_height_px(), &cr);
  }
  result.problem = std::move(p);
  return result;
}

}  // namespace stereorig
