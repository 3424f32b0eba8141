#include "datasets/sim_spec.h"

#include <gtest/gtest.h>

#include <regex>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"
#include "datasets/default_rig.h"
#include "datasets/sim_test_util.h"

namespace stereorig {
namespace {

std::string ErrorOf(const std::string& text) {
  return testing::InputErrorMessage([&] { ParseSimSpecYaml(text, "spec.yaml"); });
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// --write-default-spec's file is for editing: each number is the shortest
// text that reads back to the same double (0.6, not %.17g's
// 0.59999999999999998), and the file reads back to the very same spec.
TEST(SimSpec, TheWrittenDefaultSpecHasShortNumbersAndReadsBackIdentically) {
  const SimSpec spec = DefaultSimSpec();
  const std::string text = SimSpecToYaml(spec);
  EXPECT_NE(text.find("psf_sigma_px: 0.6\n"), std::string::npos) << text;
  EXPECT_NE(text.find("sphere_diameter_mm: 38.1\n"), std::string::npos) << text;
  // %.17g's tails: a run of 0s or 9s before the last digit.
  std::smatch tail;
  EXPECT_FALSE(std::regex_search(text, tail, std::regex("\\.[0-9]*(0{6,}|9{6,})[0-9]"))) << tail.str();
  const SimSpec read = ParseSimSpecYaml(text, "spec.yaml");
  // Shortest texts are equal exactly when the doubles are.
  EXPECT_EQ(SimSpecToYaml(read), text);
  ASSERT_EQ(read.modules.size(), spec.modules.size());
  for (size_t m = 0; m < spec.modules.size(); ++m) {
    EXPECT_EQ(read.modules[m].left.intrinsics, spec.modules[m].left.intrinsics);
    EXPECT_EQ(read.modules[m].right.intrinsics, spec.modules[m].right.intrinsics);
    EXPECT_EQ(read.modules[m].center_mm, spec.modules[m].center_mm);
  }
  EXPECT_EQ(read.render.psf_sigma_px, spec.render.psf_sigma_px);
  EXPECT_EQ(read.calibration.white_albedo, spec.calibration.white_albedo);
  EXPECT_EQ(read.scenes.tuber_semi_axes_mm, spec.scenes.tuber_semi_axes_mm);
}

TEST(SimSpec, DefaultSpecBuildsExactlyTheDefaultRig) {
  const SpecRig built = BuildSpecRig(DefaultSimSpec());
  const SimulatedRig ref = MakeDefaultRig();
  ASSERT_EQ(built.sim.rig.num_cameras(), 4);
  ASSERT_EQ(built.sim.rig.num_modules(), 2);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(built.sim.rig.camera(i).intrinsics(), ref.rig.camera(i).intrinsics());
  for (int m = 0; m < 2; ++m) {
    const Pose d = ref.rig.module(m).right_from_left.Inverse() * built.sim.rig.module(m).right_from_left;
    EXPECT_LT(d.AngleDeg(), 1e-12);
    EXPECT_LT(d.DistanceMm(), 1e-12);
  }
  const Pose d01 = ref.rig.S(0, 1).Inverse() * built.sim.rig.S(0, 1);
  EXPECT_LT(d01.AngleDeg(), 1e-9);
  EXPECT_LT(d01.DistanceMm(), 1e-9);
  // The seed's geometry: the left cameras' centres 400 mm apart along z,
  // minus the verging offsets; the projector at 200 mm from the origin.
  EXPECT_NEAR(built.projector_distance_mm[0], 200.0, 1e-12);
}

TEST(SimSpec, YamlRoundTripIsLossless) {
  SimSpec s = SmallRingSpec(3, 4, 7);
  s.render.noise = false;
  s.scenes.names = {"tuber", "cup"};
  s.calibration.scale_error_ppm = 150;
  const std::string text = SimSpecToYaml(s);
  const SimSpec back = ParseSimSpecYaml(text, "x");
  EXPECT_EQ(SimSpecToYaml(back), text);
  EXPECT_EQ(back.modules.size(), 3u);
  EXPECT_EQ(back.calibration.captures, 7);
  EXPECT_FALSE(back.render.noise);
  EXPECT_EQ(back.scenes.names, (std::vector<std::string>{"tuber", "cup"}));
}

TEST(SimSpec, BadSpecsNameTheKey) {
  const std::string good = SimSpecToYaml(DefaultSimSpec());
  EXPECT_EQ(ErrorOf(good), "");
  EXPECT_NE(ErrorOf(Replace(good, "render:\n", "render:\n  bogus_knob: 1\n")).find("bogus_knob"), std::string::npos);
  EXPECT_NE(ErrorOf(Replace(good, "samples_per_axis: 2", "samples_per_axis: 1")).find("samples_per_axis"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(good, "lines: 51", "lines: many")).find("lines"), std::string::npos);
  EXPECT_NE(ErrorOf(Replace(good, "fan_angle_deg: 23", "fan_angle_deg: -3")).find("fan_angle_deg"), std::string::npos);
  EXPECT_NE(ErrorOf(Replace(good, "names: [cup,", "names: [mug,")).find("mug"), std::string::npos);
  // Wrong number of intrinsics for the model: names the camera.
  EXPECT_NE(ErrorOf(Replace(good, "intrinsics: [1024.98", "intrinsics: [1, 1024.98")).find("left_camera"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(good, "format: stereorig-sim-spec", "format: other")).find("format"), std::string::npos);
  // A baseline in metres (0.09 for 90 mm) would render a truth rig the rig
  // file reader refuses (cameras closer than 1 mm).
  EXPECT_NE(ErrorOf(Replace(good, "baseline_mm: 90", "baseline_mm: 0.09")).find("baseline_mm: must be at least 1 mm"),
            std::string::npos);
  // A camera no lens could be (fx 100x fy: calib/core/lens_plausibility.h),
  // refused as a rig file's would be, naming the camera.
  const std::string e = ErrorOf(Replace(good, "intrinsics: [1024.98", "intrinsics: [102498"));
  EXPECT_NE(e.find("left_camera"), std::string::npos) << e;
  EXPECT_NE(e.find("pixels that far from square"), std::string::npos) << e;
}

// Module 0's cameras read out in their top 100 rows, a window their
// principal points (cy = 293 px) lie below: a real sensor mode, which the
// spec's lens check (as a rig file's) admits.
TEST(SimSpec, AWindowedCameraIsAccepted) {
  const std::string good = SimSpecToYaml(DefaultSimSpec());
  const std::string windowed = Replace(Replace(good, "imager_size: [752, 582]", "imager_size: [752, 100]"),
                                       "imager_size: [752, 582]", "imager_size: [752, 100]");
  EXPECT_EQ(ErrorOf(windowed), "");
  EXPECT_EQ(ParseSimSpecYaml(windowed, "spec.yaml").modules[0].left.height_px, 100);
  EXPECT_EQ(ParseSimSpecYaml(windowed, "spec.yaml").modules[0].right.height_px, 100);
}

// The truth's lit maps hold 8 projectors (a bit each): a ninth would light
// its scenes but no lit map, so fill and the projector warnings could not
// judge its module. Eight are read; nine refused, naming the count.
TEST(SimSpec, MoreProjectorsThanTheLitMapsHoldAreRefused) {
  SimSpec spec = DefaultSimSpec();
  while (spec.modules.size() < 8) {
    spec.modules.push_back(spec.modules[0]);
    spec.modules.back().name = "extra" + std::to_string(spec.modules.size());
  }
  EXPECT_EQ(ErrorOf(SimSpecToYaml(spec)), "");
  spec.modules.push_back(spec.modules[0]);
  spec.modules.back().name = "ninth";
  EXPECT_NE(ErrorOf(SimSpecToYaml(spec)).find("9 modules have a projector; the truth's lit maps hold 8"),
            std::string::npos)
      << ErrorOf(SimSpecToYaml(spec));
  spec.modules.back().projector.enabled = false;  // a ninth module without one is fine
  EXPECT_EQ(ErrorOf(SimSpecToYaml(spec)), "");
}

// One camera of a module windowed and not the other: the runtime refuses
// such a rig ("its two cameras' imagers differ in size"), so the spec is
// refused before any rendering, naming the module. It used to render a
// dataset no command could reconstruct.
TEST(SimSpec, AModuleWithTwoImagerSizesIsRefused) {
  const std::string good = SimSpecToYaml(DefaultSimSpec());
  const std::string one_windowed = Replace(good, "imager_size: [752, 582]", "imager_size: [400, 300]");
  EXPECT_EQ(ErrorOf(one_windowed),
            "spec.yaml: modules[0]: right_camera: imager_size: 752x582 differs from left_camera's 400x300: a "
            "module's two cameras need one imager size (window both alike)");
}

TEST(SimSpec, RingsOfOneTwoThreeModulesBuild) {
  for (int m = 1; m <= 3; ++m) {
    const SpecRig r = BuildSpecRig(SmallRingSpec(m, 4, 1));
    EXPECT_EQ(r.sim.rig.num_modules(), m);
    EXPECT_EQ(r.sim.rig.num_cameras(), 2 * m);
    std::string why;
    EXPECT_TRUE(r.sim.rig.CheckS(&why)) << why;
    if (m == 3) {
      EXPECT_NEAR(r.sim.rig.S(0, 1).AngleDeg(), 120.0, 1e-9);  // modules at 120 degrees
    }
  }
}

// The shipped three-module ring (datasets/specs/ring3.yaml, the check's
// three-module study) is the default rig with module 1 copied twice to
// 120 and 240 degrees about the vertical, 200 mm from the centre: the
// same cameras and projector, and everything else the default's.
TEST(SimSpec, TheShippedRingIsTheDefaultRigWithModuleOneCopiedTo120And240Degrees) {
  const SimSpec ring = ReadSimSpecFile(std::string(STEREORIG_SOURCE_DIR) + "/datasets/specs/ring3.yaml");
  const SimSpec def = DefaultSimSpec();
  ASSERT_EQ(ring.modules.size(), 3u);
  EXPECT_EQ(ring.modules[0].center_mm, def.modules[0].center_mm);
  for (int m = 1; m < 3; ++m) {
    const double a = 2 * M_PI * m / 3;
    EXPECT_LT((ring.modules[m].center_mm - Eigen::Vector3d(200 * std::sin(a), 0, -200 * std::cos(a))).norm(), 1e-5)
        << m;
    EXPECT_EQ(ring.modules[m].name, "module" + std::to_string(m));
  }
  EXPECT_EQ(ring.calibration.min_corners_per_camera, 0);
  // Apart from the ring's own keys, the file is the default spec.
  SimSpec as_default = ring;
  as_default.modules.resize(2);
  as_default.modules[1].center_mm = def.modules[1].center_mm;
  as_default.calibration.min_corners_per_camera = def.calibration.min_corners_per_camera;
  EXPECT_EQ(SimSpecToYaml(as_default), SimSpecToYaml(def));
}

// --- Robustness walkthrough 44 (fuzz-bounds) ---

// lines: 1000000000 was read and rendered: lines that close merge into
// nearly even light (a ripple under 3 % of it 2 sigma apart). At most those 2 line_sigma_mrad apart: 200 over the
// default 23 deg fan at 1 mrad (2 sin(11.5 deg) = 398.7 mrad of fan; 398.7 / 199 = 2.0035 mrad, 398.7 / 200 under 2).
TEST(SimSpec, ProjectorLinesThatMergeAreRefused) {
  const std::string good = SimSpecToYaml(DefaultSimSpec());
  const std::string refused = ErrorOf(Replace(good, "lines: 51", "lines: 1000000000"));
  EXPECT_NE(refused.find("projector: lines: 1000000000 lines over the fan stand 3.99e-07 mrad apart, under 2 "
                         "line_sigma_mrad (2): they merge into even light; at most 200 with this fan_angle_deg and "
                         "line_sigma_mrad"),
            std::string::npos)
      << refused;
  EXPECT_NE(ErrorOf(Replace(good, "lines: 51", "lines: 201")).find("at most 200"), std::string::npos);
  EXPECT_EQ(ErrorOf(Replace(good, "lines: 51", "lines: 200")), "");
}

// A splined lens model mrcal cannot build is refused as a rig file's is
// (calib/core/lensmodel_config.h), naming the key: the simulator's truth
// rig would otherwise abort in mrcal (SIGABRT) at the first projection.
TEST(SimSpec, ASplinedModelMrcalCannotBuildIsRefused) {
  const std::string good = SimSpecToYaml(DefaultSimSpec());
  const std::string spline = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=1_Ny=1_fov_x_deg=100";
  const std::string refused = ErrorOf(Replace(good, "lensmodel: LENSMODEL_OPENCV8", "lensmodel: " + spline));
  EXPECT_NE(refused.find("left_camera.lensmodel: '" + spline +
                         "': Nx=1 Ny=1: an order 3 spline needs Nx and Ny >= 4 (mrcal's minimum)"),
            std::string::npos)
      << refused;
}

}  // namespace
}  // namespace stereorig
