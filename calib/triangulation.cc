#include "calib/triangulation.h"

extern "C" {
#include <mrcal/triangulation.h>
}

namespace stereorig {

bool TriangulatePair(const Camera& left, const Camera& right, const Pose& right_from_left,
                     const Eigen::Vector2d& q_left, const Eigen::Vector2d& q_right, Eigen::Vector3d* p_left) {
  Eigen::Vector3d vl, vr;
  if (!left.Unproject(q_left, &vl) || !right.Unproject(q_right, &vr)) return false;
  const Pose left_from_right = right_from_left.Inverse();
  const Eigen::Vector3d vr_in_left = left_from_right.rotation() * vr;
  const Eigen::Vector3d& t = left_from_right.translation_mm();
  const mrcal_point3_t v0 = {.xyz = {vl.x(), vl.y(), vl.z()}};
  const mrcal_point3_t v1 = {.xyz = {vr_in_left.x(), vr_in_left.y(), vr_in_left.z()}};
  const mrcal_point3_t t01 = {.xyz = {t.x(), t.y(), t.z()}};
  const mrcal_point3_t p = mrcal_triangulate_leecivera_mid2(nullptr, nullptr, nullptr, &v0, &v1, &t01);
  if (p.x == 0 && p.y == 0 && p.z == 0) return false;
  *p_left = Eigen::Vector3d(p.x, p.y, p.z);
  return p_left->allFinite();
}

}  // namespace stereorig
