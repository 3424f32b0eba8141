#include "calib/core/lens_plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Geometry>  // cross()

#include "calib/core/input_error.h"
#include "calib/core/number_text.h"

namespace stereorig {

namespace {

std::string Number(double x) { return NumberText(x, 4); }

std::string Pixel(const Eigen::Vector2d& q) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.4g, %.4g) px", q.x(), q.y());
  return buf;
}

double Deg(double rad) { return rad * 180 / M_PI; }

// Angle between two unit rays, rad (atan2 of the cross and dot products:
// exact near 0, where acos is not).
double AngleRad(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// The imager's pixel centres span [0, last.x()] x [0, last.y()] px (mrcal:
// (0, 0) is the top-left pixel's centre); its area reaches half a pixel
// further.
struct Imager {
  Eigen::Vector2d last;

  bool Covers(const Eigen::Vector2d& q) const {
    return (q.array() >= -0.5).all() && (q.array() <= last.array() + 0.5).all();
  }
  Eigen::Vector2d NearestPixel(const Eigen::Vector2d& q) const { return q.cwiseMax(0).cwiseMin(last); }
  // Fraction of the way from `from` to `to` (a pixel centre) at which the
  // straight line between them reaches the pixel centres: 0 if `from` is
  // among them.
  double EntryFraction(const Eigen::Vector2d& from, const Eigen::Vector2d& to) const {
    double t = 0;
    for (int i = 0; i < 2; ++i) {
      if (from[i] < 0) t = std::max(t, from[i] / (from[i] - to[i]));
      if (from[i] > last[i]) t = std::max(t, (from[i] - last[i]) / (from[i] - to[i]));
    }
    return t;
  }
};

// Fractions in (0, 1] of the way from the principal point to a line's end
// (`length_px` away) at which the walk tests the lens, in order:
// kSamplesPerLine over the part on the imager, and over the stretch before
// it (`entry` of the way, off the imager) at the same spacing, but at most
// kSamplesPerLine samples (the work stays bounded for a far principal
// point; the imager, whose rays later steps use, is walked as finely).
std::vector<double> WalkFractions(double entry, double length_px) {
  if ((1 - entry) * length_px < 1) entry = 1;  // the line ends where it reaches the imager
  const int on_imager = entry < 1 ? kSamplesPerLine : 0;
  const int stretch =
      entry == 0   ? 0
      : entry == 1 ? kSamplesPerLine
                   : std::min(kSamplesPerLine, static_cast<int>(std::ceil(kSamplesPerLine * entry / (1 - entry))));
  std::vector<double> t;
  for (int k = 1; k <= stretch; ++k) t.push_back(entry * k / stretch);
  for (int k = 1; k <= on_imager; ++k) t.push_back(entry + (1 - entry) * k / on_imager);
  return t;
}

// Walks from the principal point to `end` and throws where the lens stops
// mapping pixels to rays one-to-one.
void CheckLineFromPrincipalPoint(const Camera& camera, const Imager& imager, const Eigen::Vector2d& end,
                                 const std::string& where) {
  const Eigen::Vector2d principal(camera.cx(), camera.cy());
  const double length_px = (end - principal).norm();
  if (length_px < 1) return;  // the principal point is (nearly) this end
  // Angles are taken from the principal point's own ray, not from +z: in a
  // splined model the spline can move the axis off (cx, cy) (mrcal's own
  // splined test model: 23 px), and the angle off +z then first falls
  // along a line from (cx, cy).
  Eigen::Vector3d principal_ray, v;
  if (!camera.Unproject(principal, &principal_ray))
    throw InputError(where, "the principal point has no ray (lens model)");
  double previous_rad = 0;
  for (const double t : WalkFractions(imager.EntryFraction(principal, end), length_px)) {
    const Eigen::Vector2d q = principal + (end - principal) * t;
    const bool on_imager = imager.Covers(q);
    const std::string there = "pixel " + Pixel(q) + ", " + Number((q - principal).norm()) +
                              " px from the principal point" + (on_imager ? "" : " (off the imager, on the way to it)");
    // Off the imager, a principal point in the wrong place puts the walk
    // where the distortion, fitted over the imager, means nothing.
    const std::string advice =
        on_imager ? "; check the distortion coefficients" : "; check the distortion coefficients and cx, cy";
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
  const std::string imager_text = std::to_string(width) + " x " + std::to_string(height) + " px imager";
  const Imager imager{Eigen::Vector2d(width - 1, height - 1)};
  const Eigen::Vector2d principal(camera.cx(), camera.cy());
  const Eigen::Vector2d corners[] = {{0, 0}, {imager.last.x(), 0}, {0, imager.last.y()}, imager.last};
  double reach_px = 0;  // to the farthest pixel
  for (const Eigen::Vector2d& corner : corners) reach_px = std::max(reach_px, (corner - principal).norm());
  if (!(reach_px <= kMaxImageCircleRadiusPx)) {
    throw InputError(where, "the principal point (cx, cy) = " + Pixel(principal) + " is " + Number(reach_px) +
                                " px from the far corner of the " + imager_text +
                                "; no lens's image circle is that big (" + Number(kMaxImageCircleRadiusPx) +
                                " px in radius at most): cx or cy mistyped, or in the wrong units?");
  }
  const double aspect = camera.fx() / camera.fy();
  if (!(aspect <= kMaxPixelAspect && aspect >= 1 / kMaxPixelAspect)) {
    throw InputError(where, "fx / fy = " + Number(camera.fx()) + " / " + Number(camera.fy()) + " = " + Number(aspect) +
                                ": pixels that far from square (limit " + Number(kMaxPixelAspect) +
                                ") are no real sensor's; a typo in fx or fy?");
  }
  // The corners, then each edge's point nearest the principal point (its
  // midpoint, seen from a principal point on the imager).
  const Eigen::Vector2d nearest = imager.NearestPixel(principal);
  const Eigen::Vector2d ends[] = {corners[0],       corners[1],
                                  corners[2],       corners[3],
                                  {0, nearest.y()}, {imager.last.x(), nearest.y()},
                                  {nearest.x(), 0}, {nearest.x(), imager.last.y()}};
  for (const Eigen::Vector2d& end : ends) CheckLineFromPrincipalPoint(camera, imager, end, where);

  // Every end was unprojected above, unless it is within a pixel of the
  // principal point, whose ray was. `nearest` is one of them: a corner, an
  // edge's point, or the principal point itself.
  Eigen::Vector3d principal_ray, nearest_ray, left_ray, right_ray;
  STEREORIG_CHECK(camera.Unproject(principal, &principal_ray) && camera.Unproject(nearest, &nearest_ray));
  const double off_axis_deg = Deg(AngleRad(nearest_ray, principal_ray));
  if (!(off_axis_deg < kMaxOffAxisDeg)) {
    throw InputError(where, "the principal point (cx, cy) = " + Pixel(principal) + " puts the " + imager_text +
                                "'s nearest pixel, " + Pixel(nearest) + ", " + Number(off_axis_deg) +
                                " deg off the optical axis (under " + Number(kMaxOffAxisDeg) +
                                " expected): beside or behind the lens; cx or cy mistyped?");
  }
  STEREORIG_CHECK(camera.Unproject(ends[4], &left_ray) && camera.Unproject(ends[5], &right_ray));
  const double fov_deg = Deg(AngleRad(left_ray, right_ray));
  if (!(fov_deg >= kMinFieldOfViewDeg)) {
    // A window far off axis spans less angle than the same pixels about the
    // axis (a pinhole's: by cos^2 of the angle off it), so a principal point
    // typed far off can be what narrows the field: named too.
    const bool off_imager = !imager.Covers(principal);
    const std::string cause = off_imager
                                  ? "fx = " + Number(camera.fx()) + " px and (cx, cy) = " + Pixel(principal) + " give"
                                  : "fx = " + Number(camera.fx()) + " px gives";
    throw InputError(where, cause + " the " + imager_text + " a field of view of " + Number(fov_deg) +
                                " deg across (at least " + Number(kMinFieldOfViewDeg) +
                                " deg expected): not a real lens; a typo in fx" + (off_imager ? ", cx or cy?" : "?"));
  }
}

}  // namespace stereorig
