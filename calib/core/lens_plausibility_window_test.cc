// Cameras read out in a window (a region of interest) of their sensor: the
// principal point, in window coordinates, lies off the imager, and the
// checks must admit them (calib/core/lens_plausibility.h) but still refuse
// what no lens could be.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "calib/core/input_error_testing.h"
#include "calib/core/lens_plausibility.h"

namespace stereorig {
namespace {

// A 1920 x 1200 sensor of 5.86 um pixels (Sony's IMX174) behind an 8 mm
// lens: f = 8 mm / 5.86 um = 1365 px, the principal point at the centre.
constexpr int kSensorWidthPx = 1920, kSensorHeightPx = 1200;
constexpr double kFocalPx = 1365;

// The lens models rig files carry (docs/formats.md), with distortion as
// calibrations give: the demo's OPENCV5 (calib/core/lens_plausibility_test.cc)
// and the default simulated rig's OPENCV8 (datasets/default_rig.cc).
std::vector<Camera> WholeSensorCameras() {
  const double f = kFocalPx, cx = 0.5 * (kSensorWidthPx - 1), cy = 0.5 * (kSensorHeightPx - 1);
  std::vector<double> splined = {f, f, cx, cy};
  splined.resize(4 + 2 * 16 * 12, 0.0);  // fov_x_deg 80 covers the sensor's 70 deg across
  return {Camera("LENSMODEL_PINHOLE", {f, f, cx, cy}, kSensorWidthPx, kSensorHeightPx),
          Camera("LENSMODEL_OPENCV5", {f, f, cx, cy, -0.1106, 0.0970, 1.84e-4, -9.17e-5, -0.0471}, kSensorWidthPx,
                 kSensorHeightPx),
          Camera("LENSMODEL_OPENCV8", {f, f, cx, cy, -0.11, 0.09, 2e-4, -1e-4, -0.02, 0, 0, 0}, kSensorWidthPx,
                 kSensorHeightPx),
          Camera("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=80", splined, kSensorWidthPx,
                 kSensorHeightPx)};
}

// `sensor`'s lens read out in a width x height window whose top-left pixel
// is the sensor's (x0, y0): the same lens, its principal point in window
// coordinates.
Camera Window(const Camera& sensor, int x0, int y0, int width, int height) {
  std::vector<double> intrinsics = sensor.intrinsics();
  intrinsics[2] -= x0, intrinsics[3] -= y0;
  return Camera(sensor.lensmodel_name(), intrinsics, width, height);
}

bool PrincipalPointIsOnImager(const Camera& c) {
  return c.cx() >= -0.5 && c.cx() <= c.imager_width_px() - 0.5 && c.cy() >= -0.5 &&
         c.cy() <= c.imager_height_px() - 0.5;
}

std::string ErrorOf(const Camera& c) {
  return testing::InputErrorMessage([&] { CheckLensIsPlausible(c, "rig.yaml: cameras[0]"); });
}

// The distance from the principal point of the pixel a refusal names.
double RefusedDistancePx(const std::string& e) {
  const size_t from = e.find(" px from the principal point");
  if (from == std::string::npos) return NAN;
  const size_t start = e.rfind(", ", from) + 2;
  return std::stod(e.substr(start, from - start));
}

TEST(LensPlausibilityWindow, CornerAndStripWindowsPass) {
  struct Roi {
    const char* name;
    int x0, y0, width, height;
  };
  const Roi rois[] = {{"640 x 480 at the top-left corner", 0, 0, 640, 480},
                      {"640 x 480 at the bottom-right corner", 1280, 720, 640, 480},
                      {"a 1920 x 200 strip at the top", 0, 0, 1920, 200},
                      {"a 1920 x 200 strip at the bottom", 0, 1000, 1920, 200},
                      {"a 200 x 1200 strip at the left", 0, 0, 200, 1200}};
  for (const Camera& sensor : WholeSensorCameras()) {
    EXPECT_EQ(ErrorOf(sensor), "") << sensor.lensmodel_name();
    for (const Roi& r : rois) {
      const Camera c = Window(sensor, r.x0, r.y0, r.width, r.height);
      ASSERT_FALSE(PrincipalPointIsOnImager(c)) << r.name;  // the premise
      EXPECT_EQ(ErrorOf(c), "") << sensor.lensmodel_name() << ", " << r.name;
    }
  }
}

// A stereographic fisheye (f = 500 px) read out in a window whose nearest
// pixel is 700 px from the principal point, 2 atan(700 / 1000) = 70 deg off
// the axis: near the rim of its field, a real lens. With the principal point
// 3000 px away, 2 atan(3) = 143 deg: the window would look backwards.
TEST(LensPlausibilityWindow, AFisheyeWindowPassesUnlessItWouldSeeBehindTheLens) {
  EXPECT_EQ(ErrorOf(Camera("LENSMODEL_STEREOGRAPHIC", {500, 500, -700, 240}, 640, 480)), "");
  const std::string e = ErrorOf(Camera("LENSMODEL_STEREOGRAPHIC", {500, 500, -3000, 240}, 640, 480));
  EXPECT_NE(e.find("rig.yaml: cameras[0]: the principal point (cx, cy) = (-3000, 240) px puts the 640 x 480 px "
                   "imager's nearest pixel, (0, 240) px, 143.1 deg off the optical axis"),
            std::string::npos)
      << e;
}

// A decimal point lost: cx = 959.500 typed as 959500. No image circle
// reaches that far (kMaxImageCircleRadiusPx).
TEST(LensPlausibilityWindow, APrincipalPointFarBeyondAnyImageCircleIsRefused) {
  for (const Camera& sensor : WholeSensorCameras()) {
    std::vector<double> intrinsics = sensor.intrinsics();
    intrinsics[2] = 959500;
    const std::string e = ErrorOf(Camera(sensor.lensmodel_name(), intrinsics, 640, 480));
    EXPECT_NE(e.find("rig.yaml: cameras[0]: the principal point (cx, cy) = (9.595e+05, 599.5) px is 9.595e+05 px "
                     "from the far corner of the 640 x 480 px imager; no lens's image circle is that big"),
              std::string::npos)
        << sensor.lensmodel_name() << ": " << e;
  }
}

// cx = 60000, within an image circle's reach, but a window 640 px wide that
// far off a pinhole's axis (at f = 1365 px) spans 640 f / (60000^2 + f^2)
// rad = 0.014 deg: refused as no field of view, naming cx, cy too.
TEST(LensPlausibilityWindow, APrincipalPointFarOffNarrowsTheFieldAndIsNamed) {
  const std::string e = ErrorOf(Camera("LENSMODEL_PINHOLE", {kFocalPx, kFocalPx, 60000, 599.5}, 640, 480));
  EXPECT_NE(e.find("fx = 1365 px and (cx, cy) = (6e+04, 599.5) px give the 640 x 480 px imager a field of view of "
                   "0.01408 deg across"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("a typo in fx, cx or cy?"), std::string::npos) << e;
}

// The demo camera (752 x 582 px, 8.3 um pixels) with cx, cy typed in um:
// (3150, 2433). Its distortion, fitted over the imager (out to r = 0.46,
// normalised), folds where d(r (1 + k1 r^2 + k2 r^4 + k3 r^6)) / dr
// = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6 turns negative: r = 1.35, 1156 px
// from the principal point, well before the imager (3000 px away). Refused
// on the way to it, pointing at cx, cy too, within one sample step of the
// fold.
TEST(LensPlausibilityWindow, APrincipalPointInUmIsRefusedWhereTheDistortionFolds) {
  const double um_per_px = 8.3, f = 1025.0168, k1 = -0.1106, k2 = 0.0970, k3 = -0.0471;
  const Camera c("LENSMODEL_OPENCV5",
                 {f, 1025.4201, 379.4664 * um_per_px, 293.1394 * um_per_px, k1, k2, 1.84e-4, -9.17e-5, k3}, 752, 582);
  double r_lo = 1, r_hi = 2;  // bisects for the fold (the derivative's first root past r = 1)
  for (int i = 0; i < 60; ++i) {
    const double r = 0.5 * (r_lo + r_hi), r2 = r * r;
    (1 + 3 * k1 * r2 + 5 * k2 * r2 * r2 + 7 * k3 * r2 * r2 * r2 > 0 ? r_lo : r_hi) = r;
  }
  const double r2 = r_lo * r_lo, fold_px = f * r_lo * (1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2);
  ASSERT_NEAR(fold_px, 1156, 1);
  const std::string e = ErrorOf(c);
  EXPECT_NE(e.find("(off the imager, on the way to it)"), std::string::npos) << e;
  EXPECT_NE(e.find("check the distortion coefficients and cx, cy"), std::string::npos) << e;
  const double refused_px = RefusedDistancePx(e);
  EXPECT_GT(refused_px, fold_px - 1) << e;  // fy is 0.04 % above fx
  EXPECT_LT(refused_px, fold_px + std::hypot(c.cx(), c.cy()) / kSamplesPerLine) << e;
}

// A fold on the window itself. k1 = -0.25 (k2, k3 zeroed): r (1 + k1 r^2)
// peaks at r = 1 / sqrt(-3 k1) = 1.155, i.e. (2/3) 1.155 f = 1051 px from
// the principal point. The top-left 640 x 480 window's far corner is 1132 px
// from it, and the way there reaches the window at 378 px: the walk to that
// corner (the first) stops on the window, within one sample step of the
// fold.
TEST(LensPlausibilityWindow, ADistortionThatFoldsOnTheWindowIsRefused) {
  const double f = kFocalPx, k1 = -0.25, r_peak = 1 / std::sqrt(-3 * k1);
  const double fold_px = f * r_peak * (1 + k1 * r_peak * r_peak);
  ASSERT_NEAR(fold_px, 1050.8, 0.1);
  const Camera c("LENSMODEL_OPENCV5", {f, f, 959.5, 599.5, k1, 0, 0, 0, 0}, 640, 480);
  const std::string e = ErrorOf(c);
  EXPECT_NE(e.find("check the distortion coefficients"), std::string::npos) << e;
  EXPECT_EQ(e.find("off the imager"), std::string::npos) << e;
  const double refused_px = RefusedDistancePx(e);
  EXPECT_GT(refused_px, fold_px) << e;
  EXPECT_LT(refused_px, fold_px + std::hypot(959.5, 599.5) / kSamplesPerLine) << e;
}

// A fold between the principal point and the window. k1 = -50: the fold is
// (2/3) f / sqrt(150) = 74 px from the principal point, the bottom-right
// 640 x 480 window's nearest pixel 342 px: no pixel of the window has a
// ray, and the walk says so where the stretch before it folds.
TEST(LensPlausibilityWindow, ADistortionThatFoldsBeforeTheWindowIsRefused) {
  const double f = kFocalPx, k1 = -50, r_peak = 1 / std::sqrt(-3 * k1);
  const double fold_px = f * r_peak * (1 + k1 * r_peak * r_peak);
  ASSERT_NEAR(fold_px, 74.3, 0.1);
  const Camera c("LENSMODEL_OPENCV5", {f, f, -320.5, -120.5, k1, 0, 0, 0, 0}, 640, 480);
  const std::string e = ErrorOf(c);
  EXPECT_NE(e.find("(off the imager, on the way to it); check the distortion coefficients and cx, cy"),
            std::string::npos)
      << e;
  const double refused_px = RefusedDistancePx(e);
  EXPECT_GT(refused_px, fold_px) << e;
  EXPECT_LT(refused_px, fold_px + std::hypot(959.5, 599.5) / kSamplesPerLine) << e;
}

}  // namespace
}  // namespace stereorig
