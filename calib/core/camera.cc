#include "camera.h"

#include <cmath>

#include "input_error.h"
#include "lensmodel_config.h"
#include "mrcal_c.h"

namespace stereorig {

struct Camera::Impl {
  mrcal_lensmodel_t lensmodel;
};

namespace {

bool ParseLensmodel(const std::string& name, mrcal_lensmodel_t* out) {
  if (!mrcal_lensmodel_from_name(out, name.c_str())) return false;
  return mrcal_lensmodel_type_is_valid(out->type);
}

}  // namespace

int Camera::NumIntrinsics(const std::string& lensmodel_name) {
  mrcal_lensmodel_t m;
  if (!ParseLensmodel(lensmodel_name, &m) || !LensmodelConfigProblem(lensmodel_name).empty()) return -1;
  return mrcal_lensmodel_num_params(&m);
}

Camera::Camera(const std::string& lensmodel_name, std::vector<double> intrinsics, int imager_width_px,
               int imager_height_px, const std::string& where)
    : lensmodel_name_(lensmodel_name),
      intrinsics_(std::move(intrinsics)),
      imager_width_px_(imager_width_px),
      imager_height_px_(imager_height_px),
      impl_(std::make_unique<Impl>()) {
  if (!ParseLensmodel(lensmodel_name_, &impl_->lensmodel)) {
    throw InputError(where, "unknown lens model '" + lensmodel_name_ +
                                "' (use an mrcal name such as LENSMODEL_OPENCV8, with its "
                                "configuration for splined models)");
  }
  if (const std::string p = LensmodelConfigProblem(lensmodel_name_); !p.empty()) throw InputError(where, p);
  const int n = mrcal_lensmodel_num_params(&impl_->lensmodel);
  if (static_cast<int>(intrinsics_.size()) != n) {
    throw InputError(where, lensmodel_name_ + " takes " + std::to_string(n) + " intrinsics, got " +
                                std::to_string(intrinsics_.size()));
  }
  for (double x : intrinsics_) {
    if (!std::isfinite(x)) throw InputError(where, "intrinsics contain NaN or Inf");
  }
  if (intrinsics_[0] <= 0 || intrinsics_[1] <= 0) {
    throw InputError(where, "focal lengths fx, fy must be positive");
  }
  if (imager_width_px_ <= 0 || imager_height_px_ <= 0) {
    throw InputError(where, "imager size must be positive");
  }
}

Camera::Camera(const Camera& o)
    : lensmodel_name_(o.lensmodel_name_),
      intrinsics_(o.intrinsics_),
      imager_width_px_(o.imager_width_px_),
      imager_height_px_(o.imager_height_px_),
      impl_(std::make_unique<Impl>(*o.impl_)) {}
Camera& Camera::operator=(const Camera& o) {
  if (this != &o) *this = Camera(o);
  return *this;
}
Camera::Camera(Camera&&) noexcept = default;
Camera& Camera::operator=(Camera&&) noexcept = default;
Camera::~Camera() = default;

const void* Camera::mrcal_lensmodel() const { return &impl_->lensmodel; }

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& p_cam, Eigen::Matrix<double, 2, 3>* dq_dp) const {
  mrcal_point3_t p = {.xyz = {p_cam.x(), p_cam.y(), p_cam.z()}};
  mrcal_point2_t q;
  mrcal_point3_t grad[2];
  const bool ok = mrcal_project(&q, dq_dp ? grad : nullptr, nullptr, &p, 1, &impl_->lensmodel, intrinsics_.data());
  STEREORIG_CHECK(ok);
  if (dq_dp) {
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 3; ++c) (*dq_dp)(r, c) = grad[r].xyz[c];
  }
  return {q.x, q.y};
}

Eigen::Matrix<double, Eigen::Dynamic, 2> Camera::ProjectMany(
    const Eigen::Matrix<double, Eigen::Dynamic, 3>& p_cam) const {
  const int n = static_cast<int>(p_cam.rows());
  std::vector<mrcal_point3_t> p(n);
  std::vector<mrcal_point2_t> q(n);
  for (int i = 0; i < n; ++i) p[i] = {.xyz = {p_cam(i, 0), p_cam(i, 1), p_cam(i, 2)}};
  const bool ok = mrcal_project(q.data(), nullptr, nullptr, p.data(), n, &impl_->lensmodel, intrinsics_.data());
  STEREORIG_CHECK(ok);
  Eigen::Matrix<double, Eigen::Dynamic, 2> out(n, 2);
  for (int i = 0; i < n; ++i) out.row(i) << q[i].x, q[i].y;
  return out;
}

bool Camera::Unproject(const Eigen::Vector2d& q_px, Eigen::Vector3d* v_unit) const {
  mrcal_point2_t q = {.xy = {q_px.x(), q_px.y()}};
  mrcal_point3_t v;
  if (!mrcal_unproject(&v, &q, 1, &impl_->lensmodel, intrinsics_.data())) return false;
  Eigen::Vector3d vv(v.x, v.y, v.z);
  if (!vv.allFinite() || vv.norm() == 0) return false;
  *v_unit = vv.normalized();
  return true;
}

Eigen::Matrix<double, Eigen::Dynamic, 3> Camera::UnprojectMany(
    const Eigen::Matrix<double, Eigen::Dynamic, 2>& q_px) const {
  const int n = static_cast<int>(q_px.rows());
  Eigen::Matrix<double, Eigen::Dynamic, 3> out(n, 3);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d v;
    if (Unproject(Eigen::Vector2d(q_px(i, 0), q_px(i, 1)), &v)) {
      out.row(i) = v.transpose();
    } else {
      out.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  }
  return out;
}

}  // namespace stereorig
