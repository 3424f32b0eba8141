#include "calib/core/lens_drift.h"

namespace stereorig {

Camera WithLensDrift(const Camera& camera, const LensDrift& drift) {
  std::vector<double> intrinsics = camera.intrinsics();
  const double scale = 1.0 + drift.focal_percent / 100.0;
  intrinsics[0] *= scale;
  intrinsics[1] *= scale;
  intrinsics[2] += drift.principal_point_px.x();
  intrinsics[3] += drift.principal_point_px.y();
  return Camera(camera.lensmodel_name(), intrinsics, camera.imager_width_px(), camera.imager_height_px(),
                "drifted lens");
}

Eigen::Vector2d DriftedPixel(const Camera& camera, const Eigen::Vector2d& q_px, double focal_fraction,
                             const Eigen::Vector2d& principal_point_px) {
  const Eigen::Vector2d c(camera.cx(), camera.cy());
  return c + principal_point_px + (1 + focal_fraction) * (q_px - c);
}

}  // namespace stereorig
