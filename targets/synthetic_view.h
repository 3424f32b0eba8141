// A synthetic image of one target face seen by a pinhole camera, for tests.
//
// Independent of the detector: it ray-casts every sub-pixel sample through an
// ideal pinhole onto the face plane and asks Target::IsBlack. Pixels follow
// mrcal's convention: (0,0) is the centre of the top-left pixel, so pixel
// (u, v) covers [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5].
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include <opencv2/core.hpp>

#include "calib/core/pose.h"
#include "targets/target.h"

namespace stereorig {

struct PinholeCamera {
  double fx_px = 1024.0, fy_px = 1024.0;  // focal lengths
  double cx_px = 375.5, cy_px = 290.5;    // principal point (mrcal convention)
  int width_px = 752, height_px = 582;
  Eigen::Vector2d Project(const Eigen::Vector3d& p_cam) const {
    return Eigen::Vector2d(fx_px * p_cam.x() / p_cam.z() + cx_px, fy_px * p_cam.y() / p_cam.z() + cy_px);
  }
};

struct SyntheticViewOptions {
  int supersample = 4;          // samples per pixel along each axis (>= 1); default 4 (16 per pixel)
  double blur_sigma_px = 0.7;   // Gaussian optical blur after sampling, px; 0 = none. Default 0.7
  double black_dn = 30.0;       // grey level of black print. Default 30
  double white_dn = 220.0;      // grey level of white paper. Default 220
  double background_dn = 90.0;  // grey level off the plate. Default 90
  double noise_sigma_dn = 0.0;  // additive Gaussian noise before 8-bit rounding, DN. Default 0
  uint64_t seed = 1;            // noise seed
};

// Renders `face` of `target` seen by `camera` at `cam_from_face` (mm).
// Returns CV_8UC1 of the camera's size.
cv::Mat RenderFace(const Target& target, Face face, const PinholeCamera& camera, const Pose& cam_from_face,
                   const SyntheticViewOptions& options = {});

// A convenient pose: the face's corner-grid centre on the optical axis at
// `distance_mm`, turned by (rx, ry, rz) degrees about the face-centre axes
// (applied z first, then y, then x), so rz = 180 is the board upside down.
Pose LookAtFace(const Target& target, double distance_mm, double rx_deg, double ry_deg, double rz_deg,
                const Eigen::Vector2d& shift_mm = Eigen::Vector2d::Zero());

}  // namespace stereorig
