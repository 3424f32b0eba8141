#include "calib/core/lens_plausibility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"

namespace stereorig {
namespace {

// The default rig's left camera, as `stereorig calibrate` wrote it for the
// demo: fx, fy, cx, cy, k1, k2, p1, p2, k3.
std::vector<double> DemoIntrinsics() {
  return {1025.0168, 1025.4201, 379.4664, 293.1394, -0.1106, 0.0970, 1.84e-4, -9.17e-5, -0.0471};
}

Camera Opencv5(const std::vector<double>& intrinsics) { return Camera("LENSMODEL_OPENCV5", intrinsics, 752, 582); }

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LensPlausibility, RealLensesPass) {
  EXPECT_NO_THROW(CheckLensIsPlausible(Opencv5(DemoIntrinsics()), "demo"));
  // Strong barrel distortion that stays one-to-one over the imager: the
  // corner is r = 0.46 (normalised) from the centre, where
  // d(r (1 + k1 r^2)) / dr = 1 + 3 k1 r^2 = 0.81 > 0.
  std::vector<double> barrel = DemoIntrinsics();
  barrel[4] = -0.3, barrel[5] = barrel[8] = 0;
  EXPECT_NO_THROW(CheckLensIsPlausible(Opencv5(barrel), "barrel"));
  // A pinhole of 300 px focal length on this imager: 103 deg across, wide
  // for a pinhole but a lens (these checks refuse what cannot be one).
  EXPECT_NO_THROW(CheckLensIsPlausible(Camera("LENSMODEL_PINHOLE", {300, 300, 375.5, 290.5}, 752, 582), "wide"));
}

// A splined stereographic lens whose spline shifts every point by the same
// 0.0224 (normalised), i.e. 23 px at fx 1025: its optical axis projects
// 23 px right of (cx, cy), as in mrcal's own splined test model. Walking
// left from (cx, cy), the rays' angle off +z first falls (towards the axis),
// which the first version of the check took for a fold; from the principal
// point's own ray it grows. A real lens: accepted.
TEST(LensPlausibility, ASplinedLensWhoseAxisIsOffThePrincipalPointPasses) {
  const int nx = 16, ny = 12;
  std::vector<double> intrinsics = {1025, 1025, 375.5, 290.5};
  for (int k = 0; k < nx * ny; ++k) intrinsics.insert(intrinsics.end(), {23.0 / 1025, 0.0});
  const Camera splined("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=50", intrinsics, 752, 582);
  Eigen::Vector3d axis_px = Eigen::Vector3d::Zero();
  axis_px.head<2>() = splined.Project(Eigen::Vector3d::UnitZ());
  ASSERT_NEAR(axis_px.x() - 375.5, 23, 0.01);  // the premise: the axis 23 px off (cx, cy)
  EXPECT_NO_THROW(CheckLensIsPlausible(splined, "splined"));
}

// cx = 900 on the 752 px wide imager was refused until windowed sensors
// were admitted: it is the demo lens read out in the left 752 columns of a
// sensor 1800 px wide. Refusals of a principal point that no window
// explains: lens_plausibility_window_test.cc.
TEST(LensPlausibility, APrincipalPointOffTheImagerPasses) {
  std::vector<double> k = DemoIntrinsics();
  k[2] = 900;
  EXPECT_NO_THROW(CheckLensIsPlausible(Opencv5(k), "rig.yaml: cameras[0]"));
}

TEST(LensPlausibility, PixelsFarFromSquareAreRefused) {
  std::vector<double> k = DemoIntrinsics();
  k[0] = 10 * k[1];  // a digit too many in fx
  EXPECT_NE(ErrorOf([&] { CheckLensIsPlausible(Opencv5(k), "c"); }).find("fx / fy = 1.025e+04 / 1025 = 10"),
            std::string::npos);
  k[0] = 2 * k[1];  // rows binned by 2 (or one field of an interlaced frame): a real sensor mode
  EXPECT_NO_THROW(CheckLensIsPlausible(Opencv5(k), "c"));
  k[0] = 0.34 * k[1];  // inside the limit the other way
  EXPECT_NO_THROW(CheckLensIsPlausible(Opencv5(k), "c"));
}

TEST(LensPlausibility, AFieldOfViewOfNothingIsRefused) {
  std::vector<double> k = DemoIntrinsics();
  k[0] = k[1] = 1e7;  // the edge pixels' centres, 751 px apart, span 751 / 1e7 rad = 0.004303 deg
  const std::string e = ErrorOf([&] { CheckLensIsPlausible(Opencv5(k), "c"); });
  EXPECT_NE(e.find("a field of view of 0.004303 deg across"), std::string::npos) << e;
  k[0] = k[1] = 4e5;  // 751 / 4e5 rad = 0.108 deg: a long telephoto, kept
  EXPECT_NO_THROW(CheckLensIsPlausible(Opencv5(k), "c"));
}

// k1 = -50: r (1 + k1 r^2) peaks at r = 1 / sqrt(-3 k1) = 0.0816 (normalised;
// k2, k3 zeroed), i.e. 0.0544 * fx = 56 px from the principal point (the
// analytic bound, not this code's), far inside the imager: beyond it no ray
// projects, so the walk outwards must stop there.
TEST(LensPlausibility, ADistortionThatFoldsBackIsRefused) {
  std::vector<double> k = DemoIntrinsics();
  k[4] = -50, k[5] = k[8] = 0;
  const double r_peak = 1 / std::sqrt(-3 * k[4]);
  const double fold_px = k[0] * r_peak * (1 + k[4] * r_peak * r_peak);
  ASSERT_NEAR(fold_px, 55.8, 0.1);
  const std::string e = ErrorOf([&] { CheckLensIsPlausible(Opencv5(k), "c"); });
  EXPECT_NE(e.find("check the distortion coefficients"), std::string::npos) << e;
  // The first pixel refused lies beyond the fold, and within one sample
  // step (the longest line: the corner, ~475 px, / 64) of it.
  const size_t from = e.find(" px from the principal point");
  ASSERT_NE(from, std::string::npos) << e;
  const size_t start = e.rfind(", ", from) + 2;
  const double refused_px = std::stod(e.substr(start, from - start));
  EXPECT_GT(refused_px, fold_px) << e;
  EXPECT_LT(refused_px, fold_px + 475.0 / kSamplesPerLine) << e;
}

// The rig file reader applies the checks, naming the file and the camera.
TEST(LensPlausibility, TheRigFileReaderRefusesAnImplausibleCamera) {
  Rig rig({Opencv5(DemoIntrinsics()), Opencv5(DemoIntrinsics())}, {"cam0", "cam1"},
          {{"module0", 0, 1, Pose::FromRotationVector({0, -0.1047, 0}, {-90, 0, 5})}}, {Pose::Identity()});
  const std::string good = RigToYaml(rig);
  EXPECT_NO_THROW(ParseRigYaml(good, "rig.yaml"));
  std::string bad = good;
  const size_t fx = bad.find("intrinsics: [") + 13;  // cameras[0]'s fx, to the comma
  bad.replace(fx, bad.find(',', fx) - fx, "1e12");
  const std::string e = ErrorOf([&] { ParseRigYaml(bad, "rig.yaml"); });
  EXPECT_EQ(e.rfind("rig.yaml", 0), 0u) << e;
  EXPECT_NE(e.find("cameras[0]"), std::string::npos) << e;
  EXPECT_NE(e.find("pixels that far from square"), std::string::npos) << e;
}

}  // namespace
}  // namespace stereorig
