#include "calib/core/typed_pose.h"

#include <Eigen/SVD>

#include "calib/core/input_error.h"

namespace stereorig {

Pose TypedRigidPose(const Eigen::Matrix4d& m, const std::string& where) {
  std::string why;
  if (IsRigid(m, 1e-9, nullptr)) return Pose::FromMatrix4(m);
  if (!IsRigid(m, kTypedRotationTolerance, &why)) throw InputError(where, why);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.topLeftCorner<3, 3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  return Pose(svd.matrixU() * svd.matrixV().transpose(), Eigen::Vector3d(m.topRightCorner<3, 1>()));
}

}  // namespace stereorig
