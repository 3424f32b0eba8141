// A camera's lens after it drifted: a focus ring turned or thermal drift
// scales the focal length, a knock moves the principal point. The image
// changes; the camera's pose and its distortion coefficients do not.
#pragma once

#include <Eigen/Core>

#include "calib/core/camera.h"

namespace stereorig {

struct LensDrift {
  double focal_percent = 0.0;                                    // fx and fy scaled by 1 + focal_percent / 100
  Eigen::Vector2d principal_point_px = Eigen::Vector2d::Zero();  // (dx, dy) added to (cx, cy)
  bool Any() const { return focal_percent != 0 || principal_point_px != Eigen::Vector2d::Zero(); }
};

// `camera` with its first four intrinsics (fx, fy, cx, cy: every mrcal model
// stereorig uses starts with them) drifted; every other intrinsic as it was.
Camera WithLensDrift(const Camera& camera, const LensDrift& drift);

// Where pixel q of `camera` lands once its lens drifted: every mrcal model
// stereorig uses maps its normalised (distorted) coordinates u to
// q = f u + c, so the drifted lens sees q' = c + d + (1 + s)(q - c), s the
// focal change as a fraction (focal_percent / 100) and d the principal
// point's move. As WithLensDrift's camera projects, without building it
// (fits that free the drift evaluate it at every step).
Eigen::Vector2d DriftedPixel(const Camera& camera, const Eigen::Vector2d& q_px, double focal_fraction,
                             const Eigen::Vector2d& principal_point_px);

}  // namespace stereorig
