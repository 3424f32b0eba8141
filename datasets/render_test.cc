// The renderer against mathematics it does not share: exact mrcal
// unprojection (Camera::Unproject at each pixel, not the ray table),
// closed-form ray-sphere and ray-plane intersection written here, and the
// projector's line geometry computed here from the spec.
#include "datasets/render.h"

#include <gtest/gtest.h>

#include <cmath>

#include "datasets/camera_rays.h"
#include "datasets/rng.h"
#include "datasets/scene_objects.h"
#include "datasets/sim_spec.h"

namespace stereorig {
namespace {

struct DefaultSetup {
  SimSpec spec = DefaultSimSpec();
  SpecRig rig = BuildSpecRig(spec);
};

TEST(CameraRays, BilinearRaysMatchExactUnprojection) {
  DefaultSetup s;
  const Camera& cam = s.rig.sim.rig.camera(1);
  const CameraRays rays(cam, 2);
  Rng rng(7);
  double worst_px = 0;
  for (int k = 0; k < 2000; ++k) {
    const int c = static_cast<int>(rng.Uniform(0, cam.imager_width_px()));
    const int r = static_cast<int>(rng.Uniform(0, cam.imager_height_px()));
    const double fu = rng.Uniform(), fv = rng.Uniform();
    const Eigen::Vector3d v = rays.Ray(c, r, fu, fv);
    // Where the blended ray lands, in pixels, against where it should.
    const Eigen::Vector2d q = cam.Project(v);
    worst_px = std::max(worst_px, (q - Eigen::Vector2d(c - 0.5 + fu, r - 0.5 + fv)).norm());
  }
  // Interpolation error of a smooth map over one pixel: second order, tiny.
  EXPECT_LT(worst_px, 2e-3);
  std::printf("worst bilinear-ray error: %.2e px\n", worst_px);
}

// Depth maps: every interior pixel's depth equals the exact intersection of
// the exactly unprojected pixel-centre ray with the analytic object.
TEST(Render, DepthMapsMatchAnalyticIntersection) {
  DefaultSetup s;
  s.spec.render.noise = false;
  const int cam_index = 0;
  const Camera& cam = s.rig.sim.rig.camera(cam_index);
  const CameraRays rays(cam, 2);
  const Pose& world_from_cam = s.rig.world_from_camera[cam_index];
  for (const std::string name : {"sphere", "plate"}) {
    const Scene scene = MakeScene(name, s.spec.scenes, s.spec.render, 11);
    const SceneRadiance rad = RenderScene(rays, world_from_cam, scene, {}, s.spec.render);
    const SceneObject& obj = scene.objects[0];
    const Pose obj_from_cam = obj.object_from_world * world_from_cam;
    int checked = 0, hits = 0;
    double worst = 0;
    for (int r = 1; r + 1 < cam.imager_height_px(); r += 2) {
      for (int c = 1; c + 1 < cam.imager_width_px(); c += 2) {
        Eigen::Vector3d v;
        ASSERT_TRUE(cam.Unproject(Eigen::Vector2d(c, r), &v));
        v.normalize();
        // The ray in the object frame.
        const Eigen::Vector3d o = obj_from_cam.translation_mm(), d = obj_from_cam.rotation() * v;
        double t = -1, margin = 0;  // margin: how far inside the silhouette (mm)
        if (name == "sphere") {
          const double rad_mm = 0.5 * s.spec.scenes.sphere_diameter_mm;
          const double b = o.dot(d), miss2 = o.squaredNorm() - b * b;
          margin = rad_mm - std::sqrt(std::max(0.0, miss2));
          if (margin > 0) t = -b - std::sqrt(rad_mm * rad_mm - miss2);
        } else {
          const Eigen::Vector3d h = 0.5 * s.spec.scenes.plate_size_mm;
          const double z = o.z() < 0 ? -h.z() : h.z();  // the face towards the camera
          const double tt = (z - o.z()) / d.z();
          const Eigen::Vector3d p = o + tt * d;
          margin = std::min(h.x() - std::abs(p.x()), h.y() - std::abs(p.y()));
          if (margin > 0) t = tt;
        }
        const float depth = rad.depth.at<float>(r, c);
        if (margin < -0.05) {
          EXPECT_EQ(depth, 0.0f) << name << " " << c << "," << r;
        }
        if (margin > 0.05) {
          ASSERT_GT(depth, 0.0f) << name << " " << c << "," << r;
          EXPECT_EQ(rad.id.at<uint8_t>(r, c), obj.id);
          // Accuracy away from the steep rim, where depth changes by mm per 1e-4 px.
          if (margin > 0.5) worst = std::max(worst, std::abs(depth - t * v.z()));
          ++hits;
        }
        ++checked;
      }
    }
    // float32 storage of ~200 mm: 1.5e-5 mm resolution; the ray table's blend error is ~1e-6 mm here.
    EXPECT_LT(worst, 1e-4) << name;
    EXPECT_GT(hits, 2000) << name;
    std::printf("%s: %d pixels checked, %d on the object, worst depth error %.2e mm\n", name.c_str(), checked, hits,
                worst);
  }
}

// Camera 0 of the default rig looking at the plate scene (seed 5) with both
// laser grids on, and the transforms the checks need.
struct PlateWithGrids {
  DefaultSetup s;
  const Camera& cam = s.rig.sim.rig.camera(0);
  const CameraRays rays{cam, 2};
  const Pose world_from_cam = s.rig.world_from_camera[0];
  const Scene scene = MakeScene("plate", s.spec.scenes, s.spec.render, 5);
  const std::vector<LaserProjector> projectors =
      MakeProjectors(s.spec, s.rig.world_from_projector, s.rig.projector_distance_mm);
  const SceneRadiance rad = RenderScene(rays, world_from_cam, scene, projectors, s.spec.render);
  const Pose obj_from_cam = scene.objects[0].object_from_world * world_from_cam;
  const Pose proj_from_cam = s.rig.world_from_projector[0].Inverse() * world_from_cam;
};

// The laser lines fall where the projector's geometry says: along image rows,
// the sub-pixel peaks of the laser image are unprojected exactly, met with
// the plate's face, and turned into the projector's direction cosines, which
// must sit on the grid sin(fan/2) * (2i/(N-1) - 1).
TEST(Render, LaserLinesFallWhereTheProjectorGeometrySays) {
  const PlateWithGrids p;
  const ProjectorSpec& ps = p.s.spec.modules[0].projector;
  const double sin_half = std::sin(0.5 * ps.fan_angle_deg * M_PI / 180.0), sigma = ps.line_sigma_mrad * 1e-3;
  auto nearest = [&](double a) {
    double best = 1e9;
    for (int i = 0; i < ps.lines; ++i) {
      const double line = sin_half * (2.0 * i / (ps.lines - 1) - 1.0);
      if (std::abs(a - line) < std::abs(best)) best = a - line;
    }
    return best;
  };
  double sum2 = 0, worst = 0;
  int peaks = 0;
  double max_l = 0;
  cv::minMaxLoc(p.rad.laser, nullptr, &max_l);
  for (int r = 2; r + 2 < p.rad.laser.rows; ++r) {
    const float* L = p.rad.laser.ptr<float>(r);
    for (int c = 2; c + 2 < p.rad.laser.cols; ++c) {
      if (!(L[c] > L[c - 1] && L[c] >= L[c + 1] && L[c] > 0.3 * max_l)) continue;
      const double den = L[c - 1] - 2.0 * L[c] + L[c + 1];
      if (den >= 0) continue;
      const double q = c + 0.5 * (L[c - 1] - L[c + 1]) / den;
      Eigen::Vector3d v;
      ASSERT_TRUE(p.cam.Unproject(Eigen::Vector2d(q, r), &v));
      const Eigen::Vector3d o = p.obj_from_cam.translation_mm(), d = p.obj_from_cam.rotation() * v.normalized();
      const double z = o.z() < 0 ? -0.5 * p.s.spec.scenes.plate_size_mm.z() : 0.5 * p.s.spec.scenes.plate_size_mm.z();
      const Eigen::Vector3d p_obj = o + (z - o.z()) / d.z() * d;
      if (std::abs(p_obj.x()) > 0.5 * p.s.spec.scenes.plate_size_mm.x() - 1 ||
          std::abs(p_obj.y()) > 0.5 * p.s.spec.scenes.plate_size_mm.y() - 1) {
        continue;
      }
      const Eigen::Vector3d u = (p.proj_from_cam * (p.obj_from_cam.Inverse() * p_obj)).normalized();
      // Peaks along a row belong to the near-vertical family (constant u_x);
      // skip those on or near a crossing line of the other family.
      if (std::abs(nearest(u.y())) < 3 * sigma || std::abs(u.y()) > sin_half) continue;
      const double e = nearest(u.x());
      sum2 += e * e;
      worst = std::max(worst, std::abs(e));
      ++peaks;
    }
  }
  ASSERT_GT(peaks, 2000);
  const double rms = std::sqrt(sum2 / peaks);
  std::printf(
      "%d laser peaks: %.4f mrad RMS, worst %.4f mrad off their line (line sigma %.2f mrad, spacing %.2f "
      "mrad)\n",
      peaks, rms * 1e3, worst * 1e3, sigma * 1e3, 2e3 * sin_half / (ps.lines - 1));
  // A parabola through three samples of a ~1 px Gaussian locates it to
  // ~0.05 px (~0.05 mrad); a wrong rotation, fan or origin would move the
  // lines by a good part of the 8 mrad spacing.
  EXPECT_LT(rms, 0.1 * sigma);
  EXPECT_LT(worst, 0.5 * sigma);
}

// Shadows: a point the projector cannot see gets no laser light. The ball
// bar's rod shadows part of the balls and vice versa; here: a sphere behind
// a sphere, along the projector's axis.
TEST(Render, LaserIsShadowed) {
  DefaultSetup s;
  Scene scene;
  const RenderSpec& rs = s.spec.render;
  ScenesSpec ss = s.spec.scenes;
  ss.wobble_shift_mm = 0;
  ss.wobble_tilt_deg = 0;
  Scene front = MakeScene("sphere", ss, rs, 1);
  const std::vector<LaserProjector> projectors =
      MakeProjectors(s.spec, s.rig.world_from_projector, s.rig.projector_distance_mm);
  // A point on the far side of the sphere as seen from projector 0 (+z side)
  // faces projector 1 only; move projector 1 away: no light there.
  const Eigen::Vector3d p_back(0, 0, 0.5 * ss.sphere_diameter_mm);
  const LaserProjector& l0 = projectors[0];
  EXPECT_TRUE(
      front.Occluded(p_back, (l0.origin_world - p_back).normalized(), 1e-3, (l0.origin_world - p_back).norm() - 1e-3));
  const Eigen::Vector3d p_front(0, 0, -0.5 * ss.sphere_diameter_mm);
  EXPECT_FALSE(front.Occluded(p_front, (l0.origin_world - p_front).normalized(), 1e-3,
                              (l0.origin_world - p_front).norm() - 1e-3));
}

// The grid-lit truth map: on the plate, a pixel is lit by projector 0 exactly
// when its surface point (exact unprojection, closed-form plane, written
// here) lies inside the square between projector 0's outermost lines (+2
// line sigmas), as the spec's fan and the projector pose say. And no line
// (laser light above a quarter of a line's peak: 2 sigma off a line's
// centre is e^-2 = 0.14 of it) falls outside the lit map.
TEST(Render, LitMapMarksTheGridEnvelope) {
  const PlateWithGrids p;
  const ProjectorSpec& ps = p.s.spec.modules[0].projector;
  const double sin_half = std::sin(0.5 * ps.fan_angle_deg * M_PI / 180.0) + 2e-3 * ps.line_sigma_mrad;
  const Eigen::Vector3d half = 0.5 * p.s.spec.scenes.plate_size_mm;
  int checked = 0, lit = 0, wrong = 0, dark_light = 0;
  for (int r = 0; r < p.cam.imager_height_px(); r += 3) {
    for (int c = 0; c < p.cam.imager_width_px(); c += 3) {
      if (p.rad.id.at<uint8_t>(r, c) == 0) {
        dark_light += p.rad.lit.at<uint8_t>(r, c) != 0;
        continue;
      }
      Eigen::Vector3d v;
      ASSERT_TRUE(p.cam.Unproject(Eigen::Vector2d(c, r), &v));
      const Eigen::Vector3d o = p.obj_from_cam.translation_mm(), d = p.obj_from_cam.rotation() * v;
      const double z = o.z() < 0 ? -half.z() : half.z();  // the face towards the camera
      const Eigen::Vector3d p_obj = o + (z - o.z()) / d.z() * d;
      // Skip pixels within 0.5 mm of the plate's edge or of the envelope's
      // border (the pixel centre's ray and this one differ by ~1e-5 mm).
      if (std::abs(p_obj.x()) > half.x() - 0.5 || std::abs(p_obj.y()) > half.y() - 0.5) continue;
      const Eigen::Vector3d u = (p.proj_from_cam * (p.obj_from_cam.Inverse() * p_obj)).normalized();
      const double margin = std::max(std::abs(u.x()), std::abs(u.y())) - sin_half;
      if (std::abs(margin) < 1e-4) continue;
      const bool inside = margin < 0;
      const bool marked = p.rad.lit.at<uint8_t>(r, c) & 1;
      wrong += inside != marked;
      lit += marked;
      ++checked;
      // Light only where the map says lit (by projector 0 or 1).
      if (p.rad.lit.at<uint8_t>(r, c) == 0) {
        EXPECT_LT(p.rad.laser.at<float>(r, c), 0.25 * ps.power_dn) << c << "," << r;
      }
    }
  }
  std::printf("lit map: %d plate pixels checked, %d lit, %d disagree\n", checked, lit, wrong);
  EXPECT_GT(checked, 5000);
  EXPECT_GT(lit, 1000);
  EXPECT_LT(lit, checked);  // the plate is larger than the grid: both cases are tested
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(dark_light, 0);  // background is never lit
}

TEST(Render, SensorNoiseHasTheModelledSpread) {
  RenderSpec r;
  r.psf_sigma_px = 0;
  const cv::Mat flat(200, 200, CV_32F, cv::Scalar(100.0f));
  const cv::Mat zero(200, 200, CV_32F, cv::Scalar(0.0f));
  const cv::Mat img = SensorImage(flat, zero, r, 3);
  cv::Scalar mean, sd;
  cv::meanStdDev(img, mean, sd);
  const double g = r.full_well_e / 255.0;
  const double expected = std::sqrt(100.0 / g + std::pow(r.read_noise_e / g, 2) + 1.0 / 12);  // + quantisation
  EXPECT_NEAR(mean[0], 100.0, 0.05);
  EXPECT_NEAR(sd[0], expected, 0.05 * expected);  // 40k samples: the sd is known to ~0.4 %
  r.noise = false;
  const cv::Mat clean = SensorImage(flat * 3.0, zero, r, 3);  // 300 DN saturates
  double lo, hi;
  cv::minMaxLoc(clean, &lo, &hi);
  EXPECT_EQ(lo, 255);
  EXPECT_EQ(hi, 255);
}

}  // namespace
}  // namespace stereorig
