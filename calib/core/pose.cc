#include "pose.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace stereorig {

Pose Pose::FromRotationVector(const Eigen::Vector3d& r_rad, const Eigen::Vector3d& t_mm) {
  const double angle = r_rad.norm();
  if (angle < 1e-300) return Pose(Eigen::Matrix3d::Identity(), t_mm);
  return Pose(Eigen::AngleAxisd(angle, r_rad / angle).toRotationMatrix(), t_mm);
}

Pose Pose::FromMatrix4(const Eigen::Matrix4d& m) {
  return Pose(Eigen::Matrix3d(m.topLeftCorner<3, 3>()), Eigen::Vector3d(m.topRightCorner<3, 1>()));
}

Eigen::Vector3d Pose::RotationVector() const {
  const Eigen::AngleAxisd aa(rotation_);
  return aa.axis() * aa.angle();
}

Eigen::Matrix4d Pose::ToMatrix4() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_;
  m.topRightCorner<3, 1>() = translation_mm_;
  return m;
}

Pose Pose::Inverse() const {
  const Eigen::Matrix3d rt = rotation_.transpose();
  return Pose(rt, -(rt * translation_mm_));
}

Pose Pose::operator*(const Pose& b_from_c) const {
  return Pose(rotation_ * b_from_c.rotation_, rotation_ * b_from_c.translation_mm_ + translation_mm_);
}

double Pose::AngleDeg() const {
  // acos of (trace-1)/2 loses precision near 0; atan2 of |sin| and cos does not.
  const Eigen::Matrix3d& r = rotation_;
  const Eigen::Vector3d axis_sin(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
  const double s = 0.5 * axis_sin.norm();
  const double c = 0.5 * (r.trace() - 1.0);
  return std::atan2(s, c) * 180.0 / M_PI;
}

bool IsRigid(const Eigen::Matrix4d& m, double tol, std::string* why) {
  if (!m.allFinite()) {
    if (why) *why = "contains NaN or Inf";
    return false;
  }
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > tol) {
    if (why) *why = "bottom row is not (0 0 0 1)";
    return false;
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double orth = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orth > tol) {
    if (why) {
      char b[120];
      std::snprintf(b, sizeof b, "rotation is not orthonormal (max |R^T R - I| = %.1e, over the %.0e allowed)", orth,
                    tol);
      *why = b;
    }
    return false;
  }
  if (r.determinant() < 0) {
    if (why) *why = "rotation is a reflection (det R < 0)";
    return false;
  }
  return true;
}

double AngleBetweenDeg(const Pose& a, const Pose& b) { return (a.Inverse() * b).AngleDeg(); }

double TranslationBetweenMm(const Pose& a, const Pose& b) { return (b.translation_mm() - a.translation_mm()).norm(); }

}  // namespace stereorig
