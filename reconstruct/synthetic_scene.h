// A small renderer of active-stereo captures of a sphere, for testing the
// runtime end to end before (and independently of) the simulator.
//
// Every camera of the rig sees a matte sphere (reference frame). Each module
// has a laser grid projector at the midpoint of its baseline, with the
// module's axes: a grid of Gaussian lines, `period_rad` apart in the
// projector's normalised image plane, turned by `grid_angle_deg`, within a
// square fan. Radiance = albedo (weakly textured) * (ambient + laser) with
// Lambert's cosine; one ray per pixel centre (no area integration), sensor
// noise, 8-bit rounding. Only the sphere is in the scene (black elsewhere).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "calib/core/rig.h"

namespace stereorig {

struct SphereSceneSpec {
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();  // reference frame
  double radius_mm = 25.0;
  bool laser_on = true;
  double period_rad = 2 * 0.2034 / 50;  // tan(11.5 deg) * 2 / 50 periods: ~1.6 mm at 200 mm, ~8 px
  double line_sigma_rad = 0.0011;       // ~0.22 mm at 200 mm, ~1.1 px
  double grid_angle_deg = 2.6;
  double fan_half_angle_deg = 11.5;
  double laser_dn = 170.0;  // peak of a line on a surface facing the projector
  double ambient_dn = 35.0;
  double texture_contrast = 0.1;
  double noise_sigma_dn = 2.0;
  uint64_t seed = 1;
};

// One CV_8UC1 image per camera (global camera index).
std::vector<cv::Mat> RenderSphereCapture(const Rig& rig, const SphereSceneSpec& spec);

// Dense samples of the sphere's surface (spacing ~ spacing_mm), for scoring.
std::vector<Eigen::Vector3d> SampleSphere(const Eigen::Vector3d& centre_mm, double radius_mm, double spacing_mm);

}  // namespace stereorig
