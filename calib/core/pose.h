// A rigid transform of 3D space, SE(3), named by the frames it joins.
//
// `Pose a_from_b` maps a point expressed in frame b to the same point
// expressed in frame a:  p_a = a_from_b * p_b.  Poses compose right to left:
//   c_from_a = c_from_b * b_from_a.
// Translations are in millimetres. Quaternions are (w, x, y, z), Hamilton
// convention, unit norm (docs/conventions.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace stereorig {

class Pose {
 public:
  Pose() : rotation_(Eigen::Matrix3d::Identity()), translation_mm_(Eigen::Vector3d::Zero()) {}
  Pose(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation_mm)
      : rotation_(rotation), translation_mm_(translation_mm) {}
  Pose(const Eigen::Quaterniond& q, const Eigen::Vector3d& translation_mm)
      : rotation_(q.normalized().toRotationMatrix()), translation_mm_(translation_mm) {}

  static Pose Identity() { return Pose(); }
  // From a rotation vector (axis * angle, radians) and a translation (mm).
  static Pose FromRotationVector(const Eigen::Vector3d& r_rad, const Eigen::Vector3d& t_mm);
  // From a 4x4 homogeneous matrix. The caller validates it first (see
  // IsRigid()); this only copies.
  static Pose FromMatrix4(const Eigen::Matrix4d& m);

  const Eigen::Matrix3d& rotation() const { return rotation_; }
  const Eigen::Vector3d& translation_mm() const { return translation_mm_; }
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(rotation_); }
  Eigen::Vector3d RotationVector() const;  // axis * angle, radians
  Eigen::Matrix4d ToMatrix4() const;

  Pose Inverse() const;
  Pose operator*(const Pose& b_from_c) const;  // (a_from_b * b_from_c) = a_from_c
  Eigen::Vector3d operator*(const Eigen::Vector3d& p_b) const { return rotation_ * p_b + translation_mm_; }

  // Rotation angle (degrees) and translation norm (mm) of this transform: the
  // size of a residual transform such as truth.Inverse() * estimate.
  double AngleDeg() const;
  double DistanceMm() const { return translation_mm_.norm(); }

 private:
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d translation_mm_;
};

// How far `b` is from `a`, two estimates of one transform: the angle of
// a^-1 b (deg) and the distance between their translations (mm; not a^-1 b's
// translation, which mixes in the rotation). As calibrate reports
// back_from_front's change.
double AngleBetweenDeg(const Pose& a, const Pose& b);
double TranslationBetweenMm(const Pose& a, const Pose& b);

// True if `m` is a rigid transform: bottom row (0 0 0 1), R^T R = I and
// det R = +1, each within `tol`. On failure `why` says which.
bool IsRigid(const Eigen::Matrix4d& m, double tol, std::string* why);

}  // namespace stereorig
