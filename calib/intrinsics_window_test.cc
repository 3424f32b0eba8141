// Stage 1 on a camera read out in a window (a region of interest) of its
// sensor: the lens's principal point keeps its place on the sensor, so in
// window coordinates (cx, cy) is off-centre, or off the image altogether.
// A seed at the window's centre is up to hundreds of pixels from the truth
// (a 320 x 240 window at a corner, below, got a 126 px focal length for a
// 1025 px lens from it, and stage 1 refused its views as fronto-parallel);
// stage 1 seeds both from the views' homographies (calib/pinhole_seed.h)
// and must find the principal point as it finds a centred one
// (intrinsics_test.cc). The corners are projected through the true
// windowed camera (calib/synthetic.h) with 0.2 px of Gaussian noise.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "calib/calib_test_util.h"
#include "calib/convergence.h"
#include "calib/core/input_error.h"
#include "calib/intrinsics.h"

namespace stereorig {
namespace {

struct SensorWindow {
  std::string name;
  int sensor_width_px, sensor_height_px;  // the whole sensor; the default rig's lens, centred on it
  int x0_px, y0_px;                       // the window's top-left pixel on the sensor
  int width_px, height_px;
};

// The default rig's camera 0 lens (OPENCV8, fx ~1025 px) on a sensor of the
// given size, read out in the window.
Camera WindowedCamera(const SensorWindow& w) {
  const Camera sensor = MakeDefaultRig().rig.camera(0);
  std::vector<double> intrinsics = sensor.intrinsics();
  // The default camera's principal point, as far from its sensor's centre
  // on a sensor of this size, then in window coordinates.
  intrinsics[2] += 0.5 * (w.sensor_width_px - sensor.imager_width_px()) - w.x0_px;
  intrinsics[3] += 0.5 * (w.sensor_height_px - sensor.imager_height_px()) - w.y0_px;
  return Camera(sensor.lensmodel_name(), intrinsics, w.width_px, w.height_px);
}

// A one-module rig whose left camera (the reference frame) is `left`, and a
// volume 200 mm ahead along the ray of the window's centre pixel, facing
// the camera: the board is in view whichever part of the lens the window
// reads.
struct WindowScene {
  Rig rig;
  Pose ref_from_volume;
};
WindowScene MakeWindowScene(const Camera& left) {
  const Rig d = MakeDefaultRig().rig;
  WindowScene s{Rig({left, d.camera(1)}, {"cam0", "cam1"}, {d.module(0)}, std::vector<Pose>{Pose::Identity()}), Pose()};
  Eigen::Vector3d ray;
  EXPECT_TRUE(
      left.Unproject(Eigen::Vector2d(0.5 * (left.imager_width_px() - 1), 0.5 * (left.imager_height_px() - 1)), &ray));
  ray.normalize();
  const Eigen::Matrix3d ref_from_volume_rotation =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray).toRotationMatrix();
  s.ref_from_volume = Pose(ref_from_volume_rotation, 200.0 * ray);
  return s;
}

TEST(IntrinsicsWindow, PrincipalPointOffTheWindowsCentreIsFound) {
  const double noise_px = 0.2;
  const std::vector<SensorWindow> windows = {
      // The default 752 x 582 sensor: an off-centre window holding the
      // principal point, and one it lies just left of (cx ~ -10.5 px).
      {"560x440 at (150, 100)", 752, 582, 150, 100, 560, 440},
      {"360x440 at (390, 70)", 752, 582, 390, 70, 360, 440},
      // At the top-left corner of a 1920 x 1200 sensor: (cx, cy) ~ (963, 602),
      // 320 and 120 px beyond the far edges of a 640 x 480 window, 640 and
      // 360 px beyond a 320 x 240 one's (whose centre sees 43 deg off axis);
      // and a strip along the sensor's bottom, cy ~ -398.
      {"640x480 at (0, 0) of 1920x1200", 1920, 1200, 0, 0, 640, 480},
      {"320x240 at (0, 0) of 1920x1200", 1920, 1200, 0, 0, 320, 240},
      {"1920x200 at (0, 1000) of 1920x1200", 1920, 1200, 0, 1000, 1920, 200},
  };
  for (const SensorWindow& w : windows) {
    SCOPED_TRACE(w.name);
    const Camera truth = WindowedCamera(w);
    const WindowScene scene = MakeWindowScene(truth);
    SyntheticOptions o;
    o.seed = 21;
    o.num_captures = 30;
    o.noise_px = noise_px;
    const TargetGeometry target = DefaultTestTarget();
    const SyntheticData data =
        MakeSyntheticCaptures(scene.rig, target, target.back_from_front, scene.ref_from_volume, o);
    const IntrinsicsResult r = CalibrateIntrinsics(0, data.input.cameras[0], target, testing::ViewsOf(data.input, 0),
                                                   IntrinsicsOptions(), "test");
    // Converged to the noise: the residual RMS per coordinate, less the
    // fitted dof (6 a board pose, 9 the lens). Its relative spread: ~1.4 %
    // expected from ~2400 residual coordinates (1 / sqrt(2 N)); measured over
    // 20 seeds (21-40) on the windows that converged, sd 1.8 %, extremes
    // -4.5 % and +6.3 %. 7.5 %: 4 sd, above the extremes.
    const double dof_share = (6.0 * r.report.num_views + 9) / (2.0 * r.report.num_corners);
    const double expected_rms_px = noise_px * std::sqrt(1 - dof_share);
    EXPECT_NEAR(r.report.rms_px, expected_rms_px, 0.075 * expected_rms_px);
    EXPECT_EQ(r.report.num_outliers, 0);
    // fx, fy, cx, cy within 4 sigma of the truth (OPENCV5 holds the true
    // lens: its rational terms are 0).
    ASSERT_EQ(r.report.intrinsics_sigma.size(), r.report.intrinsics.size());
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(r.report.intrinsics[i], truth.intrinsics()[i], 4.0 * r.report.intrinsics_sigma[i])
          << "intrinsic " << i << " (fx fy cx cy)";
    }
  }
}

// Where the solve from the first pinhole seed does not converge, stage 1
// solves from every candidate (calib/pinhole_seed.h) and keeps the best;
// where none converges, calibrate names the camera and writes no rig file
// (calib/convergence.h). Behind a 320 x 240 window at the corner of a
// 1920 x 1200 sensor (above), seeds 21-60 of these synthetic captures: from
// the first seed alone 7 of 40 were refused (fronto-parallel views, a
// negative focal length) and 8 ended at rms 1.6-62 px with fx 0-1514 px
// for the true 1025, every figure plausible; 25 converged to rms
// 0.156-0.190 px (0.2 px of noise), fx within 1.4 % of the truth. From
// every candidate 10 of the 15 converged too (0.15-0.17 px, fx within
// 1.7 %); 3 stay at 5.5-34 px and 2 are refused. Judged against the truth:
// a camera more than 10 % off in fx or 50 px off in (cx, cy) (the converged
// ones' worst: 1.7 %, 18 px; the others' best 74 %) must be named, every
// other one must pass. The seeds, the cheapest of each kind (a failed first
// seed costs ~15-20 s here: 12 more solves): two that converge from the
// first seed; 55, refused from the first seed (fronto-parallel) and
// converging from another; 49, over the limit from the first (8.1 px) and
// from every other. (Refused from every seed, the first's refusal given:
// Intrinsics' fronto-parallel test, intrinsics_test.cc.)
TEST(IntrinsicsWindow, EverySeedIsTriedBeforeACameraIsNamedAsNotConverged) {
  const SensorWindow w{"320x240 at (0, 0) of 1920x1200", 1920, 1200, 0, 0, 320, 240};
  const Camera truth = WindowedCamera(w);
  const WindowScene scene = MakeWindowScene(truth);
  const TargetGeometry target = DefaultTestTarget();
  int first_seed = 0, other_seed = 0, named = 0;
  for (const int seed : {21, 23, 55, 49}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    SyntheticOptions o;
    o.seed = seed;
    o.num_captures = 30;
    o.noise_px = 0.2;
    const SyntheticData data =
        MakeSyntheticCaptures(scene.rig, target, target.back_from_front, scene.ref_from_volume, o);
    CalibrationReport report;
    try {
      report.intrinsics.push_back(CalibrateIntrinsics(0, data.input.cameras[0], target, testing::ViewsOf(data.input, 0),
                                                      IntrinsicsOptions(), "test")
                                      .report);
    } catch (const InputError& e) {
      ADD_FAILURE() << "refused: " << e.what();
      continue;
    }
    const IntrinsicsReport& r = report.intrinsics[0];
    const std::vector<double>& v = r.intrinsics;
    const std::vector<double>& t = truth.intrinsics();
    const bool near_truth = std::abs(v[0] - t[0]) < 0.10 * t[0] && std::hypot(v[2] - t[2], v[3] - t[3]) < 50;
    const std::string problem = NotConvergedProblem(report, IntrinsicsOptions().max_rms_px);
    if (near_truth) {
      EXPECT_EQ(problem, "") << "fx " << v[0] << ", rms " << r.rms_px;
      (r.seeds_tried == 1 ? first_seed : other_seed) += 1;
    } else {
      EXPECT_EQ(problem.rfind("stage 1 did not converge: camera 0 (cam0) at rms ", 0), 0u)
          << problem << " (fx " << v[0] << ")";
      EXPECT_GT(r.seeds_tried, 1) << "given up after the first seed";
      ++named;
    }
  }
  // Each kind as measured, so that no branch above passes for want of a case.
  EXPECT_EQ(first_seed, 2);
  EXPECT_EQ(other_seed, 1);
  EXPECT_EQ(named, 1);
}

}  // namespace
}  // namespace stereorig
