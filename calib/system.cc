#include "calib/system.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <set>

#include "calib/core/input_error.h"
#include "calib/cost_functions.h"
#include "calib/horn.h"
#include "calib/intrinsics.h"
#include "calib/triangulation.h"

namespace stereorig {

void SystemOptions::Check() const {
  if (!(huber_px > 0)) throw InputError("options.huber_px", "must be > 0");
  if (min_triangulated_corners < 3) throw InputError("options.min_triangulated_corners", "must be >= 3");
  if (max_iterations < 1) throw InputError("options.max_iterations", "must be >= 1");
}

namespace {

using ObsIndex = std::map<std::pair<int, int>, const BoardObservation*>;  // (capture, camera)

ObsIndex IndexObservations(const CalibrationInput& input) {
  ObsIndex index;
  for (const BoardObservation& o : input.observations) index[{o.capture, o.camera}] = &o;
  return index;
}

// The refined right_from_left and its 1 sigma from the covariance `cov` (6x6)
// of its block's (dr rad, t mm). The rotation vector r of Exp(dr) R0 and the
// angle |r| are non-linear in dr: their Jacobian is taken by central
// differences (step 1e-6 rad: truncation ~1e-12, far below any sigma).
RefinedStereoSigma RightFromLeftSigma(int module, const PoseBlock& block, const Eigen::Matrix<double, 6, 6>& cov) {
  RefinedStereoSigma s;
  s.module = module;
  const Pose p = block.ToPose();
  const Eigen::Vector3d r = p.RotationVector(), t = p.translation_mm();
  const double deg = 180.0 / M_PI;
  Eigen::Matrix3d dr_ddr;  // d r / d dr
  constexpr double kStep = 1e-6;
  for (int i = 0; i < 3; ++i) {
    PoseBlock plus = block, minus = block;
    plus.params[i] += kStep;
    minus.params[i] -= kStep;
    dr_ddr.col(i) = (plus.ToPose().RotationVector() - minus.ToPose().RotationVector()) / (2 * kStep);
  }
  const Eigen::Matrix3d cov_r = dr_ddr * cov.block<3, 3>(0, 0) * dr_ddr.transpose();
  const Eigen::Matrix3d cov_t = cov.block<3, 3>(3, 3);
  s.baseline_mm = t.norm();
  s.rotation_deg = r.norm() * deg;
  s.rotation_vector_deg = r * deg;
  s.translation_mm = t;
  for (int i = 0; i < 3; ++i) {
    s.rotation_vector_sigma_deg(i) = std::sqrt(cov_r(i, i)) * deg;
    s.translation_sigma_mm(i) = std::sqrt(cov_t(i, i));
  }
  // The baseline |t| and the angle |r|, through their gradients t/|t|, r/|r|.
  const Eigen::Vector3d gt = t.normalized(), gr = r.normalized();
  s.baseline_sigma_mm = std::sqrt(gt.dot(cov_t * gt));
  s.rotation_sigma_deg = std::sqrt(gr.dot(cov_r * gr)) * deg;
  return s;
}

// Each capture's RMS over its corners' residual coordinates, worst first.
// `residuals`: (du, dv) per corner; `capture_of`: each corner's capture.
std::vector<SystemReport::CaptureRms> CaptureRmsOf(const std::vector<double>& residuals,
                                                   const std::vector<int>& capture_of) {
  std::map<int, std::pair<double, int>> sum_of_squares;  // capture -> (sum du^2 + dv^2, corners)
  for (size_t i = 0; i < capture_of.size() && 2 * i + 1 < residuals.size(); ++i) {
    auto& [s2, n] = sum_of_squares[capture_of[i]];
    s2 += residuals[2 * i] * residuals[2 * i] + residuals[2 * i + 1] * residuals[2 * i + 1];
    ++n;
  }
  std::vector<SystemReport::CaptureRms> out;
  for (const auto& [capture, s] : sum_of_squares)
    out.push_back({capture, std::sqrt(s.first / (2.0 * s.second)), s.second});
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.rms_px > b.rms_px; });
  return out;
}

// The q-quantile of `x` (0 <= q <= 1): the element at rank floor(q (n - 1))
// of the sorted values. `x` is reordered.
double QuantileOf(std::vector<double>* x, double q) {
  if (x->empty()) return 0.0;
  auto at = x->begin() + static_cast<std::ptrdiff_t>(q * (x->size() - 1));
  std::nth_element(x->begin(), at, x->end());
  return *at;
}

// Each camera's residual figures (SystemReport::CameraResiduals), in camera
// order. `residuals`: (du, dv) per corner; `camera_of`: each corner's camera.
std::vector<SystemReport::CameraResiduals> CameraResidualsOf(const std::vector<double>& residuals,
                                                             const std::vector<int>& camera_of) {
  std::map<int, std::vector<double>> distances_px;  // camera -> its corners' hypot(du, dv)
  std::map<int, double> sum_of_squares;
  for (size_t i = 0; i < camera_of.size() && 2 * i + 1 < residuals.size(); ++i) {
    const double du = residuals[2 * i], dv = residuals[2 * i + 1];
    distances_px[camera_of[i]].push_back(std::hypot(du, dv));
    sum_of_squares[camera_of[i]] += du * du + dv * dv;
  }
  std::vector<SystemReport::CameraResiduals> out;
  for (auto& [camera, d] : distances_px) {
    SystemReport::CameraResiduals c;
    c.camera = camera;
    c.corners = static_cast<int>(d.size());
    c.rms_px = std::sqrt(sum_of_squares[camera] / (2.0 * d.size()));
    c.median_px = QuantileOf(&d, 0.5);
    c.p90_px = QuantileOf(&d, 0.9);
    out.push_back(c);
  }
  return out;
}

// "" if a Ceres solve ended at CONVERGENCE; else how it ended, for
// SystemReport's solver_problem and horn_only_solver_problem. Its
// iterations are the steps it took, the last iteration's number:
// summary.iterations also holds Ceres's iteration 0, the starting point (a
// solve stopped at --max-iterations 1 read "after 2 iterations"), which
// num_successful_steps counts too.
std::string StoppedShort(const ceres::Solver::Summary& summary) {
  if (summary.termination_type == ceres::CONVERGENCE) return "";
  const int steps = summary.iterations.empty() ? 0 : summary.iterations.back().iteration;
  return "Ceres ended at " + std::string(ceres::TerminationTypeToString(summary.termination_type)) + " after " +
         std::to_string(steps) + (steps == 1 ? " iteration (" : " iterations (") + summary.message + ")";
}

}  // namespace

std::vector<std::map<int, ModuleCaptureView>> PoseBoardsByTriangulation(const CalibrationInput& input,
                                                                        const std::vector<ModuleCameras>& modules,
                                                                        int min_corners,
                                                                        const SystemExclusions& excluded) {
  const ObsIndex index = IndexObservations(input);
  const TargetGeometry& target = input.target;
  std::vector<std::map<int, ModuleCaptureView>> views(modules.size());
  std::set<int> captures;
  for (const BoardObservation& o : input.observations) captures.insert(o.capture);
  for (size_t k = 0; k < modules.size(); ++k) {
    const ModuleCameras& m = modules[k];
    for (int c : captures) {
      auto il = index.find({c, m.left_camera});
      auto ir = index.find({c, m.right_camera});
      if (il == index.end() || ir == index.end()) continue;
      if (excluded.ExcludesView(c, m.left_camera) || excluded.ExcludesView(c, m.right_camera) ||
          excluded.ExcludesModuleCapture(c, static_cast<int>(k)))
        continue;
      const BoardObservation& l = *il->second;
      const BoardObservation& r = *ir->second;
      if (l.face != r.face) continue;
      std::map<int, Eigen::Vector2d> qr;
      for (size_t i = 0; i < r.corner_ids.size(); ++i)
        if (!excluded.ExcludesCorner(c, m.right_camera, r.corner_ids[i])) qr[r.corner_ids[i]] = r.q_px[i];
      ModuleCaptureView v;
      v.face = l.face;
      std::vector<Eigen::Vector3d> x_face;
      for (size_t i = 0; i < l.corner_ids.size(); ++i) {
        auto it = qr.find(l.corner_ids[i]);
        if (it == qr.end() || excluded.ExcludesCorner(c, m.left_camera, l.corner_ids[i])) continue;
        Eigen::Vector3d p;
        if (!TriangulatePair(m.left, m.right, m.right_from_left, l.q_px[i], it->second, &p)) continue;
        v.corner_ids.push_back(l.corner_ids[i]);
        v.p_module.push_back(p);
        x_face.push_back(target.CornerInFace(l.corner_ids[i]));
      }
      if (static_cast<int>(v.p_module.size()) < min_corners || !CornersSpanAPlane(v.corner_ids, target.corners_x)) {
        continue;  // too few, or collinear: no board pose follows
      }
      const HornResult h = HornAbsoluteOrientation(v.p_module, x_face);
      if (!h.ok) continue;
      v.module_from_front = h.a_from_b * target.FaceFromFront(v.face);
      views[k][c] = std::move(v);
    }
  }
  return views;
}

std::vector<int> Stage3HeldIntrinsics(const std::string& lensmodel, int num_intrinsics) {
  int first_held = num_intrinsics;  // none
  if (LensmodelNeedsRegularization(lensmodel)) first_held = lensmodel.rfind("LENSMODEL_OPENCV", 0) == 0 ? 9 : 4;
  std::vector<int> held;
  for (int i = first_held; i < num_intrinsics; ++i) held.push_back(i);
  return held;
}

// Ceres says a rank-deficient J'J through glog (LOG(ERROR): "Covariance
// matrix is near rank deficient ..."), a raw line on stderr beside our own
// words. Compute's false already says it: the report's covariance status
// names it, and a refusal that follows is ours (not glog's, so not hidden).
// glog is held at FATAL for the one call (a FATAL still aborts), then given
// back; the mutex keeps two threads' calls from restoring each other's level.
bool ComputeCovarianceQuietly(ceres::Covariance* cov, const std::vector<std::pair<const double*, const double*>>& pairs,
                              ceres::Problem* problem) {
  static std::mutex glog_level_mutex;
  std::lock_guard<std::mutex> lock(glog_level_mutex);
  const int32_t level = FLAGS_minloglevel;
  FLAGS_minloglevel = google::GLOG_FATAL;
  const bool ok = cov->Compute(pairs, problem);
  FLAGS_minloglevel = level;
  return ok;
}

ceres::Covariance::Options Stage3CovarianceOptions(int num_free) {
  ceres::Covariance::Options copt;
  // SPARSE_QR fails on a rank-deficient Jacobian whatever null_space_rank
  // says; DENSE_SVD with 0 does too (-1 would truncate instead).
  copt.algorithm_type = num_free <= 3000 ? ceres::DENSE_SVD : ceres::SPARSE_QR;
  copt.null_space_rank = 0;
  // The test is on J's singular values in the parameters' own units, rad
  // beside px: a rotation's column is ~1e4 x a principal point's. OPENCV12's
  // principal points under their prior (HeldIntrinsicsPrior), a few px
  // uncertain, put the smallest at 6e-8 of the largest on the demo dataset,
  // below Ceres's default 1e-7 (sqrt(1e-14)), with column-scaled J'J
  // conditioned at 4e-10. 1e-10: a direction the data leave undetermined
  // reads at double's rounding (~1e-16 of the largest, x sqrt of the rows),
  // still refused; one merely weak is given its (wide) sigma.
  copt.min_reciprocal_condition_number = 1e-20;
  copt.num_threads = 1;
  return copt;
}

SystemResult CalibrateSystem(const CalibrationInput& input, const std::vector<ModuleCameras>& modules,
                             double corner_sigma_px, const SystemOptions& options, const SystemExclusions& excluded) {
  STEREORIG_CHECK(corner_sigma_px > 0);
  const int M = static_cast<int>(modules.size());
  const TargetGeometry& target = input.target;
  SystemResult result;
  result.modules = modules;
  SystemReport& rep = result.report;

  const auto views = PoseBoardsByTriangulation(input, modules, options.min_triangulated_corners, excluded);

  // Pairwise Horn between modules that posed the same captures.
  std::map<std::pair<int, int>, HornResult> pair_horn;
  for (int i = 0; i < M; ++i) {
    for (int j = i + 1; j < M; ++j) {
      std::vector<Eigen::Vector3d> in_i, in_j;
      int shared = 0;
      for (const auto& [c, vi] : views[i]) {
        auto it = views[j].find(c);
        if (it == views[j].end()) continue;
        const ModuleCaptureView& vj = it->second;
        ++shared;
        // Module i's triangulated corners, and where module j's board pose puts them.
        for (size_t k = 0; k < vi.corner_ids.size(); ++k) {
          const Eigen::Vector3d x_front =
              target.FaceFromFront(vi.face).Inverse() * target.CornerInFace(vi.corner_ids[k]);
          in_i.push_back(vi.p_module[k]);
          in_j.push_back(vj.module_from_front * x_front);
        }
        for (size_t k = 0; k < vj.corner_ids.size(); ++k) {
          const Eigen::Vector3d x_front =
              target.FaceFromFront(vj.face).Inverse() * target.CornerInFace(vj.corner_ids[k]);
          in_i.push_back(vi.module_from_front * x_front);
          in_j.push_back(vj.p_module[k]);
        }
      }
      if (shared == 0) continue;
      rep.shared_captures[{i, j}] = shared;
      pair_horn[{i, j}] = HornAbsoluteOrientation(in_i, in_j);
    }
  }

  // Maximum spanning tree from module 0 (Prim), by shared captures.
  std::vector<Pose> module0_from_module(M);
  std::vector<bool> in_tree(M, false);
  in_tree[0] = true;
  for (int added = 1; added < M; ++added) {
    int best = -1, bi = -1, bj = -1;
    for (const auto& [ij, n] : rep.shared_captures) {
      const auto [i, j] = ij;
      if (in_tree[i] == in_tree[j] || !pair_horn[ij].ok) continue;
      if (n > best) best = n, bi = i, bj = j;
    }
    if (best < 0) {
      std::string missing;
      for (int k = 0; k < M; ++k)
        if (!in_tree[k]) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
      throw InputError(input.source, "module(s) " + missing +
                                         " share no capture in which both they and an already-placed module posed "
                                         "the target; the S matrix is undetermined");
    }
    const HornResult& h = pair_horn[{bi, bj}];  // bi_from_bj
    const int parent = in_tree[bi] ? bi : bj, child = in_tree[bi] ? bj : bi;
    const Pose parent_from_child = parent == bi ? h.a_from_b : h.a_from_b.Inverse();
    module0_from_module[child] = module0_from_module[parent] * parent_from_child;
    in_tree[child] = true;
    rep.spanning_tree.emplace_back(parent, child);
    rep.horn_rms_mm[{parent, child}] = h.rms_mm;
  }
  result.module0_from_module_horn = module0_from_module;
  rep.module0_from_module_horn = module0_from_module;

  // ---- The bundle adjustment.
  ceres::Problem::Options popt;
  popt.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  popt.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(popt);

  std::vector<PoseBlock> s_blocks(M);
  for (int k = 0; k < M; ++k) s_blocks[k] = PoseBlock(module0_from_module[k]);
  std::vector<PoseBlock> rl_blocks(M);
  for (int k = 0; k < M; ++k) rl_blocks[k] = PoseBlock(modules[k].right_from_left);
  PoseBlock bff_block(target.back_from_front);
  PoseBlock identity_module, identity_bff, identity_rl;
  std::map<int, std::vector<double>> intrinsics;  // per global camera
  std::map<int, const Camera*> camera_of;
  std::map<int, const std::vector<double>*> stage2_covariance_of;  // per global camera
  std::map<int, std::pair<int, bool>> module_of;                   // camera -> (module, is right)
  for (int k = 0; k < M; ++k) {
    intrinsics[modules[k].left_camera] = modules[k].left.intrinsics();
    intrinsics[modules[k].right_camera] = modules[k].right.intrinsics();
    camera_of[modules[k].left_camera] = &modules[k].left;
    camera_of[modules[k].right_camera] = &modules[k].right;
    stage2_covariance_of[modules[k].left_camera] = &modules[k].left_intrinsics_covariance;
    stage2_covariance_of[modules[k].right_camera] = &modules[k].right_intrinsics_covariance;
    module_of[modules[k].left_camera] = {k, false};
    module_of[modules[k].right_camera] = {k, true};
  }

  // Board poses, seeded from the first module (in tree order) that posed them.
  std::map<int, PoseBlock> boards;
  std::vector<int> order = {0};
  for (const auto& e : rep.spanning_tree) order.push_back(e.second);
  for (int k : order) {
    for (const auto& [c, v] : views[k]) {
      if (!boards.count(c)) boards[c] = PoseBlock(module0_from_module[k] * v.module_from_front);
    }
  }
  rep.num_captures = static_cast<int>(boards.size());

  // A module's views of a capture in which its two cameras saw different
  // faces stay set aside, as stage 2 decided (excluded.module_captures): the
  // board pose (one per capture) and back_from_front could hold them, but a
  // face misread by the detector looks the same, and the module posed no
  // board there to check them against.
  std::vector<ceres::ResidualBlockId> corner_blocks;
  std::vector<int> corner_capture;  // per corner block
  std::vector<int> corner_camera;   // per corner block
  bool any_back = false;
  for (const BoardObservation& o : input.observations) {
    auto b = boards.find(o.capture);
    auto mo = module_of.find(o.camera);
    if (b == boards.end() || mo == module_of.end()) continue;
    const auto [k, is_right] = mo->second;
    if (excluded.ExcludesModuleCapture(o.capture, k)) continue;
    // The earlier stages' verdicts (SystemExclusions). The Huber loss bounds
    // each corner's pull but does not remove it: a grazing view's corners,
    // outliers in their camera's own solve, pulled a ring's intrinsics 1.6 px
    // off the truth and its baselines by 0.03 mm. A view stage 1 dropped was
    // judged not to determine its board pose; its corners stay out whole.
    if (excluded.ExcludesView(o.capture, o.camera)) {
      if (!o.corner_ids.empty()) ++rep.num_skipped_views;
      rep.num_skipped_view_corners += static_cast<int>(o.corner_ids.size());
      continue;
    }
    const bool back = o.face == Face::kBack;
    any_back |= back;
    for (size_t i = 0; i < o.corner_ids.size(); ++i) {
      if (excluded.ExcludesCorner(o.capture, o.camera, o.corner_ids[i])) {
        ++rep.num_skipped_outlier_corners;
        continue;
      }
      CornerPointFunctor g;
      g.x_face = target.CornerInFace(o.corner_ids[i]);
      g.back_face = back;
      g.right_camera = is_right;
      PoseBlock* module_block = k == 0 ? &identity_module : &s_blocks[k];
      PoseBlock* bff = back ? &bff_block : &identity_bff;
      PoseBlock* rl = is_right ? &rl_blocks[k] : &identity_rl;
      g.R0[0] = b->second.R0;
      g.R0[1] = module_block->R0;
      g.R0[2] = bff->R0;
      g.R0[3] = rl->R0;
      corner_blocks.push_back(problem.AddResidualBlock(
          CornerReprojectionCost::Create(g, *camera_of[o.camera], o.q_px[i]), new ceres::HuberLoss(options.huber_px),
          std::vector<double*>{b->second.params, module_block->params, bff->params, rl->params,
                               intrinsics[o.camera].data()}));
      corner_capture.push_back(o.capture);
      corner_camera.push_back(o.camera);
    }
  }
  rep.num_residual_corners = static_cast<int>(corner_blocks.size());
  // Without mrcal's regularisation, the intrinsics the corners alone do not
  // determine (Stage3HeldIntrinsics) are refined under stage 2's covariance
  // of them (HeldIntrinsicsPrior), which carries their uncertainty into S's;
  // without that covariance they stay at their stage-2 values, and S's
  // 1 sigma is said to be conditional on them.
  int num_prior_residuals = 0;
  std::vector<int> held_without_prior;
  struct HeldPrior {
    std::vector<int> held;     // indices in the camera's intrinsics
    Eigen::MatrixXd cov_held;  // stage 2's covariance of them
  };
  std::map<int, HeldPrior> prior_of;  // per global camera refined under a prior
  for (auto& [cam, v] : intrinsics) {
    if (!problem.HasParameterBlock(v.data())) continue;
    const int n = static_cast<int>(v.size());
    const std::vector<int> held = Stage3HeldIntrinsics(camera_of[cam]->lensmodel_name(), n);
    if (held.empty()) continue;
    std::unique_ptr<ceres::CostFunction> prior(
        options.refine_intrinsics ? HeldIntrinsicsPrior::Create(v, held, *stage2_covariance_of[cam], corner_sigma_px)
                                  : nullptr);
    if (prior) {
      HeldPrior& hp = prior_of[cam];
      hp.held = held;
      hp.cov_held.resize(held.size(), held.size());
      for (size_t i = 0; i < held.size(); ++i)
        for (size_t j = 0; j < held.size(); ++j)
          hp.cov_held(i, j) = (*stage2_covariance_of[cam])[held[i] * n + held[j]];
    } else {
      problem.SetManifold(v.data(), new ceres::SubsetManifold(n, held));
      held_without_prior.push_back(cam);
    }
  }
  // The priors: one over a module's two cameras where stage 2 gave the
  // cross-covariance of its two lenses (solved jointly, they are not
  // independent: ModuleCameras::left_right_intrinsics_covariance), else one
  // per camera. cross_held[{left, right}]: the cross-covariance of their
  // held terms, for the correction of the covariance below.
  std::map<std::pair<int, int>, Eigen::MatrixXd> cross_held;
  std::set<int> in_joint_prior;
  for (const ModuleCameras& m : modules) {
    auto pl = prior_of.find(m.left_camera), pr = prior_of.find(m.right_camera);
    if (pl == prior_of.end() || pr == prior_of.end() || pl->second.held != pr->second.held) continue;
    const std::vector<int>& held = pl->second.held;
    const int n = static_cast<int>(intrinsics[m.left_camera].size()), h = static_cast<int>(held.size());
    if (m.left_right_intrinsics_covariance.size() != static_cast<size_t>(n) * n) continue;
    Eigen::MatrixXd cross(h, h);
    for (int i = 0; i < h; ++i)
      for (int j = 0; j < h; ++j) cross(i, j) = m.left_right_intrinsics_covariance[held[i] * n + held[j]];
    Eigen::MatrixXd joint(2 * h, 2 * h);
    joint << pl->second.cov_held, cross, cross.transpose(), pr->second.cov_held;
    ceres::CostFunction* prior = HeldIntrinsicsPrior::CreateJoint(
        {intrinsics[m.left_camera], intrinsics[m.right_camera]}, held, joint, corner_sigma_px);
    if (!prior) continue;  // not positive definite: each camera's own, below
    problem.AddResidualBlock(prior, nullptr, intrinsics[m.left_camera].data(), intrinsics[m.right_camera].data());
    num_prior_residuals += 2 * h;
    cross_held[{m.left_camera, m.right_camera}] = cross;
    in_joint_prior.insert(m.left_camera);
    in_joint_prior.insert(m.right_camera);
  }
  for (auto& [cam, hp] : prior_of) {
    if (in_joint_prior.count(cam)) continue;
    problem.AddResidualBlock(
        HeldIntrinsicsPrior::Create(intrinsics[cam], hp.held, *stage2_covariance_of[cam], corner_sigma_px), nullptr,
        intrinsics[cam].data());
    num_prior_residuals += static_cast<int>(hp.held.size());
  }
  if (!options.refine_intrinsics) {
    rep.sigma_conditional_on = "every camera's intrinsics, held at stage 2's values (the intrinsics not refined)";
  } else if (!held_without_prior.empty()) {
    std::string cams;
    for (int c : held_without_prior) cams += (cams.empty() ? "" : ", ") + std::to_string(c);
    rep.sigma_conditional_on = "camera(s) " + cams +
                               "'s k4.. (OPENCV8/12) or spline knots, held at stage 2's values: stage 2 gave no "
                               "covariance of them";
  }
  for (PoseBlock* p : {&identity_module, &identity_bff, &identity_rl}) {
    if (problem.HasParameterBlock(p->params)) problem.SetParameterBlockConstant(p->params);
  }
  // back_from_front is refined under the target file's prior, axis by axis:
  // an axis whose sigma is 0 is known exactly (the limit of a prior whose
  // sigma goes to 0) and held at the file's value, the others refined and
  // judged (back_from_front_vs_file). Only a file whose every sigma is 0
  // holds it whole. Before, a single 0 held all six, and the file went
  // unjudged: a thickness typed in metres passed, unrefined, beside a
  // rotation sigma of 0.
  std::vector<int> bff_held;
  for (int i = 0; i < 6; ++i)
    if (!(target.back_from_front_sigma(i) > 0)) bff_held.push_back(i);
  const bool bff_free = any_back && options.refine_back_from_front && target.double_sided && bff_held.size() < 6;
  if (bff_free) {
    problem.AddResidualBlock(BackFromFrontPrior::Create(target.back_from_front.translation_mm(),
                                                        target.back_from_front_sigma, corner_sigma_px),
                             nullptr, bff_block.params);
    // Held at the file's: dr = 0 (R0 is the file's rotation), t the file's.
    if (!bff_held.empty()) problem.SetManifold(bff_block.params, new ceres::SubsetManifold(6, bff_held));
  }

  auto set_free = [&](bool s, bool rl, bool bff, bool intr) {
    for (int k = 1; k < M; ++k)
      if (problem.HasParameterBlock(s_blocks[k].params)) {
        s ? problem.SetParameterBlockVariable(s_blocks[k].params)
          : problem.SetParameterBlockConstant(s_blocks[k].params);
      }
    for (int k = 0; k < M; ++k)
      if (problem.HasParameterBlock(rl_blocks[k].params)) {
        rl ? problem.SetParameterBlockVariable(rl_blocks[k].params)
           : problem.SetParameterBlockConstant(rl_blocks[k].params);
      }
    if (problem.HasParameterBlock(bff_block.params)) {
      bff ? problem.SetParameterBlockVariable(bff_block.params) : problem.SetParameterBlockConstant(bff_block.params);
    }
    for (auto& [cam, v] : intrinsics)
      if (problem.HasParameterBlock(v.data())) {
        intr ? problem.SetParameterBlockVariable(v.data()) : problem.SetParameterBlockConstant(v.data());
      }
  };
  // The corners' residuals, each block's (du, dv), px, without the loss.
  // An evaluation that failed would leave them unread (zeros, a small RMS):
  // they read NaN, and the solve is reported as one that did not converge.
  auto corner_residuals = [&]() {
    ceres::Problem::EvaluateOptions eo;
    eo.residual_blocks = corner_blocks;
    eo.apply_loss_function = false;
    std::vector<double> r;
    if (!problem.Evaluate(eo, nullptr, &r, nullptr, nullptr)) {
      rep.solver_problem = "its residuals could not be evaluated (a projection failed)";
      r.assign(2 * corner_blocks.size(), std::numeric_limits<double>::quiet_NaN());
    }
    return r;
  };
  auto rms = [](const std::vector<double>& r) {
    double s2 = 0;
    for (double x : r) s2 += x * x;
    return r.empty() ? 0.0 : std::sqrt(s2 / r.size());
  };

  ceres::Solver::Options sopt;
  sopt.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  sopt.max_num_iterations = options.max_iterations;
  sopt.num_threads = 1;
  sopt.function_tolerance = 1e-12;
  sopt.parameter_tolerance = 1e-12;
  sopt.gradient_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  // Horn-only: S and the stereo pairs held, the board poses solved.
  set_free(false, false, false, false);
  ceres::Solve(sopt, &problem, &summary);
  // Checked as the full solve's is, but only reported: this solve seeds the
  // full adjustment, which is judged on its own, and gives the Horn-only
  // RMS, which is then where it stopped, not Horn's.
  rep.horn_only_solver_problem = StoppedShort(summary);
  rep.horn_only_stopped_short = !rep.horn_only_solver_problem.empty();
  rep.horn_reprojection_rms_px = rms(corner_residuals());
  // Residuals not evaluated (corner_residuals said so in solver_problem,
  // which the full solve's ending replaces below): said after how it ended.
  if (!rep.solver_problem.empty())
    rep.horn_only_solver_problem += (rep.horn_only_stopped_short ? "; " : "") + rep.solver_problem;
  // The full adjustment.
  set_free(true, options.refine_stereo, bff_free, options.refine_intrinsics);
  ceres::Solve(sopt, &problem, &summary);
  // What the full adjustment left is judged, not the Horn-only step's
  // evaluation above (a seed the full solve moved away from): its problem
  // replaced. Only CONVERGENCE is a solution: NO_CONVERGENCE (the iteration limit),
  // FAILURE and USER_FAILURE leave the parameters wherever the solve
  // stopped, whatever their RMS reads (OPENCV12 with its k4..k6 freed: 100
  // iterations, an RMS at the noise, S 2.95 mm off the truth).
  rep.solver_problem = StoppedShort(summary);
  rep.max_iterations = options.max_iterations;
  rep.solver_at_iteration_limit = summary.termination_type == ceres::NO_CONVERGENCE;
  const std::vector<double> refined = corner_residuals();
  rep.refined_reprojection_rms_px = rms(refined);
  std::vector<double> distances_px;
  for (size_t i = 0; i + 1 < refined.size(); i += 2) distances_px.push_back(std::hypot(refined[i], refined[i + 1]));
  if (!distances_px.empty()) {
    auto mid = distances_px.begin() + distances_px.size() / 2;
    std::nth_element(distances_px.begin(), mid, distances_px.end());
    rep.refined_median_corner_residual_px = *mid;
  }
  rep.refined_capture_rms = CaptureRmsOf(refined, corner_capture);
  rep.refined_camera_residuals = CameraResidualsOf(refined, corner_camera);
  rep.solver_summary = summary.BriefReport();

  for (int k = 0; k < M; ++k) result.module0_from_module.push_back(k == 0 ? Pose::Identity() : s_blocks[k].ToPose());
  rep.module0_from_module = result.module0_from_module;
  for (int k = 0; k < M; ++k) {
    result.modules[k].right_from_left = rl_blocks[k].ToPose();
    if (options.refine_intrinsics) {
      result.modules[k].left = Camera(modules[k].left.lensmodel_name(), intrinsics[modules[k].left_camera],
                                      modules[k].left.imager_width_px(), modules[k].left.imager_height_px());
      result.modules[k].right = Camera(modules[k].right.lensmodel_name(), intrinsics[modules[k].right_camera],
                                       modules[k].right.imager_width_px(), modules[k].right.imager_height_px());
    }
  }
  rep.back_from_front = bff_block.ToPose();
  rep.back_from_front_change_deg = AngleBetweenDeg(target.back_from_front, rep.back_from_front);
  rep.back_from_front_change_mm = TranslationBetweenMm(target.back_from_front, rep.back_from_front);
  if (bff_free) {
    Eigen::Matrix<double, 6, 1> off;
    off << PlateTurnDeg(rep.back_from_front, target.back_from_front),
        rep.back_from_front.translation_mm() - target.back_from_front.translation_mm();
    // The error model of a file: its rotation error a turn of the back
    // print about the BACK face's origin, |t| (~100 mm) from the front's, so
    // that t (the front's origin in the back's frame) moves by the lever arm
    // d t = d r x t besides its own error. The simulator's misaligned print
    // (datasets/target_render.cc) and the tests' files (calib_test_util.cc,
    // MakeScene) are drawn so; the translation sigma alone does not hold it
    // (an honest test file read chi-square 28 without the term). Stage 3's
    // prior (BackFromFrontPrior) treats the rotation and t as independent
    // instead, a turn about the FRONT face's origin (which leaves t alone):
    // the judgement's variance is the wider of the two models, so that an
    // honest file under either is not refused. Not measured: the refusal
    // rate on honest files (the 3 in 1000 is chi-square theory).
    const Eigen::Matrix<double, 6, 1>& sg = target.back_from_front_sigma;
    const Eigen::Vector3d r2 = (sg.head<3>() * M_PI / 180.0).array().square();
    const Eigen::Vector3d t = target.back_from_front.translation_mm();
    Eigen::Matrix<double, 6, 1> variance = sg.array().square();
    variance(3) += r2.y() * t.z() * t.z() + r2.z() * t.y() * t.y();
    variance(4) += r2.z() * t.x() * t.x() + r2.x() * t.z() * t.z();
    variance(5) += r2.x() * t.y() * t.y() + r2.y() * t.x() * t.x();
    // A held axis did not move and is not judged: no degree of freedom.
    for (int i : bff_held) variance(i) = 0;
    rep.back_from_front_vs_file = ComparePlates(off, variance);
  }

  // 1 sigma of S[0][k], of each free right_from_left and of each camera's
  // free intrinsics, from the covariance of the adjustment, scaled by the
  // residual variance (Ceres assumes unit-variance residuals).
  //
  // Gauge: the problem has none left. Module 0's pose is a constant identity
  // and its left camera's frame is the reference, every other block is tied
  // to the corners, and back_from_front has its prior, as OPENCV8/12's k4..
  // (and a spline's knots) have theirs. Held without a prior, those stay
  // out through a SubsetManifold: their covariance is computed in the
  // manifold's tangent space and returned in the ambient space with zero
  // rows/columns. A data set that leaves a direction undetermined gets no
  // sigma (Stage3CovarianceOptions), not a pseudo-inverse's.
  rep.covariance_status = "not computed";
  if (options.compute_covariance) {
    int num_free = 0;
    std::vector<double*> blocks;
    problem.GetParameterBlocks(&blocks);
    for (double* b : blocks)
      if (!problem.IsParameterBlockConstant(b)) num_free += problem.ParameterBlockTangentSize(b);
    ceres::Covariance cov(Stage3CovarianceOptions(num_free));
    auto is_free = [&](const double* b) {
      return problem.HasParameterBlock(b) && !problem.IsParameterBlockConstant(const_cast<double*>(b));
    };
    // The blocks whose 1 sigma is reported, and with them (for the
    // correction below) their covariance with the intrinsics under a prior.
    std::vector<const double*> reported;
    for (int k = 1; k < M; ++k)
      if (is_free(s_blocks[k].params)) reported.push_back(s_blocks[k].params);
    for (int k = 0; k < M; ++k)
      if (is_free(rl_blocks[k].params)) reported.push_back(rl_blocks[k].params);
    for (const auto& [cam, v] : intrinsics)
      if (is_free(v.data())) reported.push_back(v.data());
    // Each unordered pair once (Ceres gives (b, a) as (a, b)'s transpose).
    std::set<std::pair<const double*, const double*>> pair_set;
    for (const double* x : reported) {
      pair_set.emplace(x, x);
      for (const auto& [cam, hp] : prior_of) {
        const double* h = intrinsics[cam].data();
        pair_set.emplace(std::min(x, h), std::max(x, h));
      }
    }
    const std::vector<std::pair<const double*, const double*>> pairs(pair_set.begin(), pair_set.end());
    if (!pairs.empty() && ComputeCovarianceQuietly(&cov, pairs, &problem)) {
      // The held intrinsics' prior residuals count as observations of them.
      const double n_res = 2.0 * corner_blocks.size() + num_prior_residuals;
      const double rms = rep.refined_reprojection_rms_px;
      const double sigma2 = rms * rms * n_res / std::max(1.0, n_res - num_free);
      const double deg = 180.0 / M_PI;
      using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
      auto block = [&](const double* a, const double* b) {
        RowMajor c(problem.ParameterBlockSize(a), problem.ParameterBlockSize(b));
        STEREORIG_CHECK(cov.GetCovarianceBlock(a, b, c.data()));
        return RowMajor(sigma2 * c);
      };
      // The prior counts stage 2's corners a second time: they are stage
      // 3's too, and stage 2's covariance C_h of the terms under it is what
      // they (with the regularisation) left, so that stage 3's posterior of
      // them, C'_h, comes out narrower than C_h: what the corners say of
      // them stage 2 already took in. So their covariance is set back to
      // C_h, and every block x follows through its regression on them (G =
      // C'_xh C'_h^-1, in the joint Gaussian the normal equations'
      // d x / d theta_h):
      //   C_x = C'_x + G (C_h - C'_h) G'.
      // A module's two cameras' C_h are joint where stage 2 gave their
      // cross-covariance (cross_held), the modules' independent. Measured without
      // it, OPENCV12 on the default rig, 25 captures, 10 seeds: S's largest
      // |error| / sigma 1.2 - 5.3 (with it 1.0 - 3.7); on the demo dataset
      // S 1.84, the principal points 2.9 (with it 1.41, 2.3).
      int num_held = 0;
      for (const auto& [cam, hp] : prior_of) num_held += static_cast<int>(hp.held.size());
      Eigen::MatrixXd c_h_stage2 = Eigen::MatrixXd::Zero(num_held, num_held);
      Eigen::MatrixXd c_h_stage3 = Eigen::MatrixXd::Zero(num_held, num_held);
      int oi = 0;
      for (const auto& [cam_i, hi] : prior_of) {
        const int ni = static_cast<int>(hi.held.size());
        c_h_stage2.block(oi, oi, ni, ni) = hi.cov_held;
        int oj = 0;
        for (const auto& [cam_j, hj] : prior_of) {
          const int nj = static_cast<int>(hj.held.size());
          if (auto x = cross_held.find({cam_i, cam_j}); x != cross_held.end())
            c_h_stage2.block(oi, oj, ni, nj) = x->second;
          if (auto x = cross_held.find({cam_j, cam_i}); x != cross_held.end())
            c_h_stage2.block(oi, oj, ni, nj) = x->second.transpose();
          const RowMajor c = block(intrinsics[cam_i].data(), intrinsics[cam_j].data());
          for (int a = 0; a < ni; ++a)
            for (size_t b = 0; b < hj.held.size(); ++b) c_h_stage3(oi + a, oj + b) = c(hi.held[a], hj.held[b]);
          oj += static_cast<int>(hj.held.size());
        }
        oi += ni;
      }
      const Eigen::LDLT<Eigen::MatrixXd> c_h_stage3_ldlt(c_h_stage3);
      auto covariance_of = [&](const double* x) {
        RowMajor c = block(x, x);
        if (num_held == 0) return c;
        RowMajor c_xh(c.rows(), num_held);
        int o = 0;
        for (const auto& [cam, hp] : prior_of) {
          const RowMajor c_xh_cam = block(x, intrinsics[cam].data());
          for (size_t a = 0; a < hp.held.size(); ++a) c_xh.col(o + a) = c_xh_cam.col(hp.held[a]);
          o += static_cast<int>(hp.held.size());
        }
        const Eigen::MatrixXd g = c_h_stage3_ldlt.solve(c_xh.transpose()).transpose();
        c += g * (c_h_stage2 - c_h_stage3) * g.transpose();
        return c;
      };
      for (int k = 1; k < M; ++k) {
        if (!is_free(s_blocks[k].params)) continue;
        const RowMajor c = covariance_of(s_blocks[k].params);
        STransformSigma s;
        s.module = k;
        for (int i = 0; i < 3; ++i) {
          s.rotation_deg(i) = std::sqrt(c(i, i)) * deg;
          s.translation_mm(i) = std::sqrt(c(3 + i, 3 + i));
        }
        rep.sigma.push_back(s);
      }
      for (int k = 0; k < M; ++k) {
        if (!is_free(rl_blocks[k].params)) continue;
        const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> c = covariance_of(rl_blocks[k].params);
        rep.stereo_sigma.push_back(RightFromLeftSigma(k, rl_blocks[k], c));
      }
      for (const auto& [cam, v] : intrinsics) {
        if (!is_free(v.data())) continue;
        const RowMajor c = covariance_of(v.data());
        RefinedIntrinsicsSigma s;
        s.camera = cam;
        s.intrinsics = v;
        for (int i = 0; i < c.rows(); ++i) s.sigma.push_back(std::sqrt(std::max(0.0, c(i, i))));
        rep.intrinsics_sigma.push_back(std::move(s));
      }
      rep.covariance_status = "ok";
    } else if (!pairs.empty()) {
      rep.covariance_status =
          "not computed: the adjustment leaves a direction of its parameters undetermined (ceres::Covariance found "
          "its Jacobian rank-deficient, or nearly), so no 1 sigma of S, of the refined stereo pairs or of the "
          "intrinsics is given";
    }
  }
  return result;
}

}  // namespace stereorig
