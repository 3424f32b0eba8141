// The renderer: light transport from analytic objects and laser projectors to
// radiance images (in DN, before the sensor), and the sensor model that turns
// radiance into an 8-bit image (PSF blur, stray light, speckle, shot and read
// noise, quantisation, saturation). docs/simulator.md describes every knob.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "calib/core/pose.h"
#include "datasets/camera_rays.h"
#include "datasets/scene_objects.h"
#include "datasets/sim_spec.h"

namespace stereorig {

// The simulator's "up" (world y points down).
inline const Eigen::Vector3d kWorldUp(0, -1, 0);

// Room light on a Lambertian surface of albedo 1 with outward normal n (DN):
// a diffuse part plus a part from above (a hemispherical sky).
inline double AmbientIrradianceDn(const RenderSpec& r, const Eigen::Vector3d& n_world) {
  return r.ambient_dn * ((1.0 - r.ambient_directional) + r.ambient_directional * 0.5 * (1.0 + n_world.dot(kWorldUp)));
}

// One laser DOE projector in the world.
struct LaserProjector {
  Pose projector_from_world;
  Eigen::Vector3d origin_world = Eigen::Vector3d::Zero();
  double sin_half_fan = 0;  // sin(fan / 2)
  int lines = 0;
  double sigma = 0;  // line 1-sigma in direction-cosine units (rad)
  double power_dn = 0;
  double ref_distance_mm = 200;  // where power_dn applies (1/r^2 falloff)

  // Relative line intensity (0..2, 2 at a crossing) along unit direction
  // u_projector (projector frame).
  double Pattern(const Eigen::Vector3d& u_projector) const;
  // True if unit direction u_projector (projector frame) lies inside the
  // grid's envelope: the square between the outermost lines of both
  // families, widened by 2 sigma so the outermost lines themselves are in
  // (|u_x|, |u_y| <= sin(fan/2) + 2 sigma, in front).
  bool InEnvelope(const Eigen::Vector3d& u_projector) const;
  // Distance (direction-cosine units) from u to the nearest line of family
  // 0 (constant u_x) or 1 (constant u_y); the line index in *line.
  double DistanceToLine(const Eigen::Vector3d& u_projector, int family, int* line) const;
};

// The enabled projectors of a spec'd rig, in the world.
std::vector<LaserProjector> MakeProjectors(const SimSpec& spec, const std::vector<Pose>& world_from_projector,
                                           const std::vector<double>& projector_distance_mm);

struct SceneRadiance {
  cv::Mat passive;  // CV_32F (H,W): room light only, mean over the pixel's samples (DN)
  cv::Mat laser;    // CV_32F (H,W): laser light only, mean over the samples (DN)
  cv::Mat depth;    // CV_32F (H,W): z (camera frame, mm) where the pixel-centre ray meets a surface; 0 = none
  cv::Mat id;       // CV_8U (H,W): object id at the pixel centre; 0 = background
  // CV_8U (H,W): which grids light the surface point at the pixel centre:
  // bit k set if projector k (of the `projectors` list) has it inside its
  // grid envelope (LaserProjector::InEnvelope), facing it, and not in its
  // shadow; 0 = background or unlit. The denominator of the fill rate
  // (reconstruct/fill_score.h): lines and the dark gaps between them alike.
  cv::Mat lit;
};

// Ray-casts every pixel with n x n stratified samples (render.samples_per_axis).
// Laser light reaches a point only if the projector sees it (shadow ray).
SceneRadiance RenderScene(const CameraRays& rays, const Pose& world_from_cam, const Scene& scene,
                          const std::vector<LaserProjector>& projectors, const RenderSpec& render);

// A camera's fixed veiling glare: a smooth ramp with mean stray_light_dn, its
// direction drawn from `key`. CV_32F (H,W).
cv::Mat StrayLight(int width, int height, const RenderSpec& render, uint64_t key);

// Laser speckle: a multiplicative field (mean 1, 1-sigma speckle_contrast,
// grain speckle_grain_px), independent per camera and capture. CV_32F.
cv::Mat SpeckleField(int width, int height, const RenderSpec& render, uint64_t key);

// The sensor: radiance (DN, CV_32F) + stray light -> PSF blur -> shot and read
// noise (if render.noise) -> rounding -> clipping to [0, 255]. CV_8U.
cv::Mat SensorImage(const cv::Mat& radiance_dn, const cv::Mat& stray_dn, const RenderSpec& render, uint64_t key);

}  // namespace stereorig
