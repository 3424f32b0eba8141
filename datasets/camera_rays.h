// A camera's rays, unprojected once through the real lens model and reused
// for every capture: mrcal_unproject is an iterative solve (about a
// microsecond a pixel), far too slow to call per sample per image.
//
// The table holds the unit ray through every pixel CORNER: (W+1) x (H+1)
// directions at q = (c - 0.5, r - 0.5) in mrcal's pixel convention ((0,0) is
// the centre of the top-left pixel), so pixel (c, r) covers
// [c-0.5, c+0.5] x [r-0.5, r+0.5]. A ray anywhere inside a pixel is the
// bilinear blend of its four corner rays; the lens map is smooth on that
// scale, so the blend's error is below 1e-4 px for the lenses simulated here
// (camera_rays_test measures it against Camera::Unproject).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "calib/core/camera.h"

namespace stereorig {

class CameraRays {
 public:
  // Unprojects (W+1)(H+1) corners on `threads` threads. A corner mrcal cannot
  // unproject (far outside a wild lens's valid area) is marked invalid.
  CameraRays(const Camera& camera, int threads);

  int width() const { return width_; }
  int height() const { return height_; }
  // Corner (i, j), i in [0, W], j in [0, H]: unit ray in the camera frame.
  const Eigen::Vector3d& Corner(int i, int j) const { return corners_[static_cast<size_t>(j) * (width_ + 1) + i]; }
  bool CornerValid(int i, int j) const { return valid_[static_cast<size_t>(j) * (width_ + 1) + i] != 0; }
  bool PixelValid(int c, int r) const {
    return CornerValid(c, r) && CornerValid(c + 1, r) && CornerValid(c, r + 1) && CornerValid(c + 1, r + 1);
  }
  // The (not normalised) ray through (c - 0.5 + fu, r - 0.5 + fv), fu, fv in [0, 1].
  Eigen::Vector3d Ray(int c, int r, double fu, double fv) const {
    const Eigen::Vector3d& a = Corner(c, r);
    const Eigen::Vector3d& b = Corner(c + 1, r);
    const Eigen::Vector3d& d = Corner(c, r + 1);
    const Eigen::Vector3d& e = Corner(c + 1, r + 1);
    return (1 - fv) * ((1 - fu) * a + fu * b) + fv * ((1 - fu) * d + fu * e);
  }

 private:
  int width_ = 0, height_ = 0;
  std::vector<Eigen::Vector3d> corners_;  // (H+1, W+1) row-major
  std::vector<unsigned char> valid_;
};

}  // namespace stereorig
