#include "calib/projection_uncertainty.h"

#include <cholmod.h>

#include <cmath>
#include <vector>

#include "calib/core/input_error.h"

extern "C" {
#include <mrcal/mrcal-internal.h>
#include <mrcal/poseutils.h>
}

namespace stereorig {

struct ProjectionUncertaintyEvaluator::Impl {
  const MrcalProblem* problem = nullptr;
  cholmod_common common{};
  cholmod_sparse* Jt = nullptr;      // (Nstate, Nmeasurements): J transposed, packed (unitless) state
  cholmod_factor* factor = nullptr;  // of Jt Jt' = J'J
  int num_states = 0;
  int num_measurements = 0;
  int num_measurements_observations = 0;  // the leading rows of J that come from the boards
  bool has_regularization = false;
  double sigma_px = 0.0;
  bool ok = false;
  std::string message;

  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    if (Jt) cholmod_free_sparse(&Jt, &common);
    cholmod_finish(&common);
  }
};

ProjectionUncertaintyEvaluator::ProjectionUncertaintyEvaluator(const MrcalProblem& p)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.problem = &p;
  cholmod_start(&m.common);
  m.num_states = p.num_states();
  m.num_measurements = p.num_measurements();
  m.num_measurements_observations = p.num_measurements_boards();
  m.has_regularization = m.num_measurements_observations != m.num_measurements;

  const int nnz = _mrcal_num_j_nonzero(p.num_observations(), 0, p.corners_x, p.corners_y, p.num_intrinsics_cameras,
                                       p.num_extrinsics(), p.num_frames(), 0, 0, p.observations.data(), nullptr,
                                       p.selections, &p.lensmodel);
  m.Jt = cholmod_allocate_sparse(m.num_states, m.num_measurements, nnz, 1, 1, 0, CHOLMOD_REAL, &m.common);
  std::vector<double> b(m.num_states), x(m.num_measurements);
  const mrcal_problem_constants_t constants = {.point_min_range = -1.0, .point_max_range = -1.0};
  if (!mrcal_optimizer_callback(
          b.data(), m.num_states * static_cast<int>(sizeof(double)), x.data(),
          m.num_measurements * static_cast<int>(sizeof(double)), m.Jt, p.intrinsics.data(), p.extrinsics_fromref.data(),
          p.frames_toref.data(), nullptr, nullptr, p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0, 0,
          p.observations.data(), nullptr, p.num_observations(), 0, p.pool.data(), &p.lensmodel, p.imagersizes.data(),
          p.selections, &constants, p.spacing_mm, p.corners_x, p.corners_y, false)) {
    m.message = "mrcal_optimizer_callback failed";
    return;
  }
  m.factor = cholmod_analyze(m.Jt, &m.common);
  if (!m.factor || !cholmod_factorize(m.Jt, m.factor, &m.common) || m.common.status != CHOLMOD_OK) {
    m.message = "CHOLMOD could not factorise J'J (is every frame observed?)";
    return;
  }

  // sigma: np.std of the non-outlier chessboard residuals (x and y pooled),
  // as mrcal.projection_uncertainty() does when not given one.
  const int n_corners = p.corners_x * p.corners_y;
  double sum = 0, sum2 = 0;
  long n = 0;
  for (int i = 0; i < p.num_observations() * n_corners; ++i) {
    if (p.pool[i].z <= 0.0) continue;
    for (int k = 0; k < 2; ++k) {
      const double r = x[2 * i + k];
      sum += r;
      sum2 += r * r;
      ++n;
    }
  }
  if (n < 2) {
    m.message = "no inlier observations";
    return;
  }
  const double mean = sum / n;
  m.sigma_px = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  m.ok = true;
}

ProjectionUncertaintyEvaluator::~ProjectionUncertaintyEvaluator() = default;
bool ProjectionUncertaintyEvaluator::ok() const { return impl_->ok; }
const std::string& ProjectionUncertaintyEvaluator::message() const { return impl_->message; }
double ProjectionUncertaintyEvaluator::observed_pixel_sigma_px() const { return impl_->sigma_px; }

ProjectionUncertainty ProjectionUncertaintyEvaluator::AtPoint(int icam_intrinsics, const Eigen::Vector3d& p_cam) const {
  const Impl& m = *impl_;
  STEREORIG_CHECK(m.ok);
  const MrcalProblem& p = *m.problem;
  const int Nstate = m.num_states;
  const int Nparams = p.num_params();

  int icam_extrinsics = -1;
  STEREORIG_CHECK(mrcal_corresponding_icam_extrinsics(&icam_extrinsics, icam_intrinsics, p.num_intrinsics_cameras,
                                                      p.num_extrinsics(), p.num_observations(), p.observations.data(),
                                                      0, nullptr));

  // dq/db, shape (2, Nstate), in full (unpacked) units first.
  StateGradient dq_db = StateGradient::Zero(2, Nstate);

  // p_ref: the point in the reference frame.
  Eigen::Vector3d p_ref = p_cam;
  const double* rt_cam_ref = nullptr;
  if (icam_extrinsics >= 0) {
    rt_cam_ref = &p.extrinsics_fromref[icam_extrinsics].r.x;
    mrcal_transform_point_rt_inverted(p_ref.data(), nullptr, nullptr, rt_cam_ref, p_cam.data());
  }

  // The mean over frames of (frame -> ref)(ref -> frame)(p_ref): its value is
  // p_ref; its gradient wrt each frame's rt is d(rt * p_frame)/d(rt) / Nframes.
  const bool frames_optimized = p.selections.do_optimize_frames && p.num_frames() > 0;
  Eigen::Matrix<double, 3, Eigen::Dynamic> dpref_dframes;
  if (frames_optimized) {
    const int Nframes = p.num_frames();
    dpref_dframes.resize(3, 6 * Nframes);
    for (int k = 0; k < Nframes; ++k) {
      const double* rt_ref_frame = &p.frames_toref[k].r.x;
      Eigen::Vector3d p_frame, p_back;
      mrcal_transform_point_rt_inverted(p_frame.data(), nullptr, nullptr, rt_ref_frame, p_ref.data());
      Eigen::Matrix<double, 3, 6, Eigen::RowMajor> J_rt;
      mrcal_transform_point_rt(p_back.data(), J_rt.data(), nullptr, rt_ref_frame, p_frame.data());
      dpref_dframes.block<3, 6>(0, 6 * k) = J_rt / Nframes;
    }
  }

  // Projection and its gradients.
  const double* intrinsics = &p.intrinsics[icam_intrinsics * Nparams];
  mrcal_point3_t pc = {.xyz = {p_cam.x(), p_cam.y(), p_cam.z()}};
  mrcal_point2_t q;
  mrcal_point3_t dq_dp_raw[2];
  std::vector<double> dq_dintr(2 * Nparams);
  STEREORIG_CHECK(mrcal_project(&q, dq_dp_raw, dq_dintr.data(), &pc, 1, &p.lensmodel, intrinsics));
  Eigen::Matrix<double, 2, 3> dq_dpcam;
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) dq_dpcam(r, c) = dq_dp_raw[r].xyz[c];

  // Intrinsics: only the optimized slice.
  if (p.selections.do_optimize_intrinsics_core || p.selections.do_optimize_intrinsics_distortions) {
    const mrcal_lensmodel_metadata_t meta = mrcal_lensmodel_metadata(&p.lensmodel);
    const int Ncore = meta.has_core ? 4 : 0;
    const int i0 = (meta.has_core && !p.selections.do_optimize_intrinsics_core) ? Ncore : 0;
    const int i1 = p.selections.do_optimize_intrinsics_distortions ? Nparams : Ncore;
    const int istate =
        mrcal_state_index_intrinsics(icam_intrinsics, p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0,
                                     0, p.num_observations(), p.selections, &p.lensmodel);
    for (int r = 0; r < 2; ++r)
      for (int i = i0; i < i1; ++i) dq_db(r, istate + i - i0) = dq_dintr[r * Nparams + i];
  }

  const int istate_frames =
      frames_optimized ? mrcal_state_index_frames(0, p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0, 0,
                                                  p.num_observations(), p.selections, &p.lensmodel)
                       : -1;
  if (icam_extrinsics >= 0) {
    Eigen::Vector3d p_cam2;
    Eigen::Matrix<double, 3, 6, Eigen::RowMajor> dpcam_drt;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> dpcam_dpref;
    mrcal_transform_point_rt(p_cam2.data(), dpcam_drt.data(), dpcam_dpref.data(), rt_cam_ref, p_ref.data());
    if (p.selections.do_optimize_extrinsics) {
      const int istate_ext =
          mrcal_state_index_extrinsics(icam_extrinsics, p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0,
                                       0, p.num_observations(), p.selections, &p.lensmodel);
      dq_db.block(0, istate_ext, 2, 6) = dq_dpcam * dpcam_drt;
    }
    if (frames_optimized) {
      dq_db.block(0, istate_frames, 2, dpref_dframes.cols()) = dq_dpcam * dpcam_dpref * dpref_dframes;
    }
  } else if (frames_optimized) {
    dq_db.block(0, istate_frames, 2, dpref_dframes.cols()) = dq_dpcam * dpref_dframes;
  }

  ProjectionUncertainty out;
  out.covariance_px2 = Covariance(dq_db);
  const double a = out.covariance_px2(0, 0), bb = out.covariance_px2(1, 0), cc = out.covariance_px2(1, 1);
  out.rms_stdev_px = std::sqrt(0.5 * (a + cc));
  out.worst_direction_stdev_px = std::sqrt(0.5 * (a + cc) + std::sqrt(0.25 * (a - cc) * (a - cc) + bb * bb));
  return out;
}

Eigen::MatrixXd ProjectionUncertaintyEvaluator::Covariance(const StateGradient& dy_db_unpacked,
                                                           bool regularisation_as_prior) const {
  const Impl& m = *impl_;
  STEREORIG_CHECK(m.ok);
  STEREORIG_CHECK(dy_db_unpacked.cols() == m.num_states);
  const MrcalProblem& p = *m.problem;
  const int Nstate = m.num_states;
  const int k = static_cast<int>(dy_db_unpacked.rows());
  // To the packed state: d/db* = d/db D. mrcal's "unpack" multiplies by D.
  StateGradient dy_db = dy_db_unpacked;
  for (int r = 0; r < k; ++r) {
    mrcal_unpack_solver_state_vector(dy_db.row(r).data(), p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(),
                                     0, 0, p.selections, &p.lensmodel);
  }

  // A = inv(J'J) dy_db' : (Nstate, k), column-major.
  cholmod_common* c = &impl_->common;
  cholmod_dense* B = cholmod_allocate_dense(Nstate, k, Nstate, CHOLMOD_REAL, c);
  double* Bx = static_cast<double*>(B->x);
  for (int r = 0; r < k; ++r)
    for (int i = 0; i < Nstate; ++i) Bx[r * Nstate + i] = dy_db(r, i);
  cholmod_dense* A = cholmod_solve(CHOLMOD_A, m.factor, B, c);
  STEREORIG_CHECK(A != nullptr);
  const Eigen::Map<const Eigen::MatrixXd> Am(static_cast<const double*>(A->x), Nstate, k);

  Eigen::MatrixXd var = Eigen::MatrixXd::Zero(k, k);
  if (m.has_regularization && !regularisation_as_prior) {
    // Var = A' J_obs' J_obs A: sum over the observation rows of J of the
    // outer product of (J_row . A).
    const int* Jp = static_cast<const int*>(m.Jt->p);
    const int* Ji = static_cast<const int*>(m.Jt->i);
    const double* Jx = static_cast<const double*>(m.Jt->x);
    Eigen::VectorXd v(k);
    for (int row = 0; row < m.num_measurements_observations; ++row) {
      v.setZero();
      for (int e = Jp[row]; e < Jp[row + 1]; ++e) v += Jx[e] * Am.row(Ji[e]).transpose();
      var += v * v.transpose();
    }
  } else {
    var = dy_db * Am;
  }
  cholmod_free_dense(&A, c);
  cholmod_free_dense(&B, c);
  return var * (m.sigma_px * m.sigma_px);
}

Eigen::MatrixXd ProjectionUncertaintyEvaluator::IntrinsicsCovariance(int icam, bool regularisation_as_prior) const {
  return JointIntrinsicsCovariance({icam}, regularisation_as_prior);
}

Eigen::MatrixXd ProjectionUncertaintyEvaluator::JointIntrinsicsCovariance(const std::vector<int>& icams,
                                                                          bool regularisation_as_prior) const {
  const MrcalProblem& p = *impl_->problem;
  const int Nparams = p.num_params(), k = static_cast<int>(icams.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(k * Nparams, k * Nparams);
  const mrcal_lensmodel_metadata_t meta = mrcal_lensmodel_metadata(&p.lensmodel);
  const int Ncore = meta.has_core ? 4 : 0;
  const int i0 = (meta.has_core && !p.selections.do_optimize_intrinsics_core) ? Ncore : 0;
  const int i1 = p.selections.do_optimize_intrinsics_distortions ? Nparams : Ncore;
  if (i1 <= i0) return out;
  const int m = i1 - i0;
  // Every camera's free parameters in one gradient: their joint covariance.
  StateGradient g = StateGradient::Zero(k * m, impl_->num_states);
  for (int a = 0; a < k; ++a) {
    const int istate =
        mrcal_state_index_intrinsics(icams[a], p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0, 0,
                                     p.num_observations(), p.selections, &p.lensmodel);
    for (int i = 0; i < m; ++i) g(a * m + i, istate + i) = 1.0;
  }
  const Eigen::MatrixXd c = Covariance(g, regularisation_as_prior);
  for (int a = 0; a < k; ++a)
    for (int b = 0; b < k; ++b) out.block(a * Nparams + i0, b * Nparams + i0, m, m) = c.block(a * m, b * m, m, m);
  return out;
}

Eigen::Matrix<double, 6, 6> ProjectionUncertaintyEvaluator::ExtrinsicsCovariance(int icam_extrinsics) const {
  const MrcalProblem& p = *impl_->problem;
  STEREORIG_CHECK(p.selections.do_optimize_extrinsics && icam_extrinsics >= 0 && icam_extrinsics < p.num_extrinsics());
  const int istate =
      mrcal_state_index_extrinsics(icam_extrinsics, p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0, 0,
                                   p.num_observations(), p.selections, &p.lensmodel);
  StateGradient g = StateGradient::Zero(6, impl_->num_states);
  for (int i = 0; i < 6; ++i) g(i, istate + i) = 1.0;
  return Covariance(g);
}

ProjectionUncertainty ProjectionUncertaintyEvaluator::AtPixel(int icam_intrinsics, const Eigen::Vector2d& q_px,
                                                              double range_mm) const {
  const MrcalProblem& p = *impl_->problem;
  mrcal_point2_t q = {.xy = {q_px.x(), q_px.y()}};
  mrcal_point3_t v;
  STEREORIG_CHECK(mrcal_unproject(&v, &q, 1, &p.lensmodel, &p.intrinsics[icam_intrinsics * p.num_params()]));
  Eigen::Vector3d vv(v.x, v.y, v.z);
  return AtPoint(icam_intrinsics, vv.normalized() * range_mm);
}

}  // namespace stereorig
