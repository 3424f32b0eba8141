#include "calib/core/lens_plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>  // cross()

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

std::string Number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

std::string Pixel(const Eigen::Vector2d& q) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.4g, %.4g) px", q.x(), q.y());
  return buf;
}

// Angle between two unit rays, rad (atan2 of the cross and dot products:
// exact near 0, where acos is not).
double AngleRad(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Walks from the principal point to `end` and throws where the lens stops
// mapping pixels to rays one-to-one.
void CheckLineFromPrincipalPoint(const Camera& camera, const Eigen::Vector2d& end, const std::string& where) {
  const Eigen::Vector2d principal(camera.cx(), camera.cy());
  if ((end - principal).norm() < 1) return;  // the principal point is (nearly) this end
  // Angles are taken from the principal point's own ray, not from +z: in a
  // splined model the spline can move the axis off (cx, cy) (mrcal's own
  // splined test model: 23 px), and the angle off +z then first falls
  // along a line from (cx, cy).
  Eigen::Vector3d principal_ray, v;
  if (!camera.Unproject(principal, &principal_ray))
    throw InputError(where, "the principal point has no ray (lens model)");
  double previous_rad = 0;
  for (int k = 1; k <= kSamplesPerLine; ++k) {
    const Eigen::Vector2d q = principal + (end - principal) * (double(k) / kSamplesPerLine);
    const std::string there =
        "pixel " + Pixel(q) + ", " + Number((q - principal).norm()) + " px from the principal point";
    const std::string advice = "; check the distortion coefficients";
    if (!camera.Unproject(q, &v)) throw InputError(where, "the lens model gives no ray for " + there + advice);
    if ((camera.Project(v) - q).norm() > kRoundTripTolerancePx) {
      throw InputError(where, "the lens model does not map the imager one-to-one: " + there +
                                  " does not project back onto itself" + advice);
    }
    const double rad = AngleRad(v, principal_ray);
    if (!(rad > previous_rad)) {
      throw InputError(where, "the lens model folds back: moving out to " + there +
                                  " the ray turns back towards the principal point's" + advice);
    }
    previous_rad = rad;
  }
}

}  // namespace

void CheckLensIsPlausible(const Camera& camera, const std::string& where) {
  const int width = camera.imager_width_px(), height = camera.imager_height_px();
  const std::string imager = std::to_string(width) + " x " + std::to_string(height) + " px imager";
  const Eigen::Vector2d principal(camera.cx(), camera.cy());
  if (!(principal.x() >= -0.5 && principal.x() <= width - 0.5 && principal.y() >= -0.5 &&
        principal.y() <= height - 0.5)) {
    throw InputError(where, "the principal point (cx, cy) = " + Pixel(principal) + " lies off the " + imager);
  }
  const double aspect = camera.fx() / camera.fy();
  if (!(aspect <= kMaxPixelAspect && aspect >= 1 / kMaxPixelAspect)) {
    throw InputError(where, "fx / fy = " + Number(camera.fx()) + " / " + Number(camera.fy()) + " = " + Number(aspect) +
                                ": pixels that far from square (limit " + Number(kMaxPixelAspect) +
                                ") are no real sensor's; a typo in fx or fy?");
  }
  // Pixel centres at the imager's edges (mrcal: (0, 0) is the top-left
  // pixel's centre).
  const double right = width - 1, bottom = height - 1;
  const Eigen::Vector2d ends[] = {{0, 0},
                                  {right, 0},
                                  {0, bottom},
                                  {right, bottom},
                                  {0, principal.y()},
                                  {right, principal.y()},
                                  {principal.x(), 0},
                                  {principal.x(), bottom}};
  for (const Eigen::Vector2d& end : ends) CheckLineFromPrincipalPoint(camera, end, where);

  // Both ends were unprojected above, unless one is the principal point,
  // whose ray was.
  Eigen::Vector3d left_ray, right_ray;
  STEREORIG_CHECK(camera.Unproject(ends[4], &left_ray) && camera.Unproject(ends[5], &right_ray));
  const double fov_deg = std::acos(std::clamp(left_ray.dot(right_ray), -1.0, 1.0)) * 180 / M_PI;
  if (!(fov_deg >= kMinFieldOfViewDeg)) {
    throw InputError(where, "fx = " + Number(camera.fx()) + " px gives the " + imager + " a field of view of " +
                                Number(fov_deg) + " deg across (at least " + Number(kMinFieldOfViewDeg) +
                                " deg expected): not a real lens; a typo in fx?");
  }
}

}  // namespace stereorig
