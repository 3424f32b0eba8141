#include "calib/horn.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "calib/core/input_error.h"

namespace stereorig {

HornResult HornAbsoluteOrientation(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                                   const std::vector<double>& weights) {
  STEREORIG_CHECK(a.size() == b.size());
  STEREORIG_CHECK(weights.empty() || weights.size() == a.size());
  HornResult out;
  const size_t n = a.size();
  if (n < 3) {
    out.message = "fewer than 3 points";
    return out;
  }
  double wsum = 0;
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    wsum += w;
    ca += w * a[i];
    cb += w * b[i];
  }
  ca /= wsum;
  cb /= wsum;

  // M(x, y) = sum w (b_i - cb)_x (a_i - ca)_y: Horn's S_xy, with b the
  // "left" (source) set and a the "right" (destination) set.
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    M += w * (b[i] - cb) * (a[i] - ca).transpose();
  }
  // Collinear (or coincident) points leave the rotation about their line free.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd_b(M);
  const Eigen::Vector3d& sv = svd_b.singularValues();
  if (sv(1) <= 1e-12 * std::max(1.0, sv(0))) {
    out.message = "points are collinear";
    return out;
  }
  const double Sxx = M(0, 0), Sxy = M(0, 1), Sxz = M(0, 2);
  const double Syx = M(1, 0), Syy = M(1, 1), Syz = M(1, 2);
  const double Szx = M(2, 0), Szy = M(2, 1), Szz = M(2, 2);
  Eigen::Matrix4d N;
  N << Sxx + Syy + Szz, Syz - Szy, Szx - Sxz, Sxy - Syx,  //
      Syz - Szy, Sxx - Syy - Szz, Sxy + Syx, Szx + Sxz,   //
      Szx - Sxz, Sxy + Syx, -Sxx + Syy - Szz, Syz + Szy,  //
      Sxy - Syx, Szx + Sxz, Syz + Szy, -Sxx - Syy + Szz;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(N);
  const Eigen::Vector4d e = eig.eigenvectors().col(3);  // eigenvalues ascend: the largest is last
  const Eigen::Quaterniond q(e(0), e(1), e(2), e(3));   // (w, x, y, z)
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  out.a_from_b = Pose(R, ca - R * cb);
  double s2 = 0;
  for (size_t i = 0; i < n; ++i) s2 += (a[i] - out.a_from_b * b[i]).squaredNorm();
  out.rms_mm = std::sqrt(s2 / n);
  out.ok = true;
  return out;
}

}  // namespace stereorig
