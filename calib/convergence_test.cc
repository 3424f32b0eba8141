// NotConvergedProblem (convergence.h) on reports built by hand: which stage
// it names, and that every RMS it reads is held to the limit. A real stage 1
// that did not converge: IntrinsicsWindow.EverySeedIsTriedBeforeACameraIsNamedAsNotConverged;
// the refusal through the command: CalibrateCli.AStageOverTheRmsLimitWritesNoRigFile.
#include "calib/convergence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace stereorig {
namespace {

// Two modules of two cameras, every stage at 0.2 px.
CalibrationReport ConvergedReport() {
  CalibrationReport r;
  r.num_modules = 2;
  for (int k = 0; k < 4; ++k) {
    IntrinsicsReport c;
    c.camera = k;
    c.camera_name = "cam" + std::to_string(k);
    c.rms_px = 0.2;
    c.worst_views.push_back({7, 0.3, 40});
    r.intrinsics.push_back(c);
  }
  for (int m = 0; m < 2; ++m) {
    StereoReport s;
    s.module = m;
    s.module_name = "module" + std::to_string(m);
    s.rms_px = 0.2;
    r.stereo.push_back(s);
  }
  r.system.refined_reprojection_rms_px = 0.2;
  r.system.refined_median_corner_residual_px = 0.24;
  r.capture_names[7] = "007";
  return r;
}

bool StartsWith(const std::string& s, const std::string& head) { return s.rfind(head, 0) == 0; }

TEST(Convergence, EveryStageWithinTheLimitPasses) {
  EXPECT_EQ(NotConvergedProblem(ConvergedReport(), 1.0), "");
  // Stage 3's median distance 0.24 px against sqrt(2 ln 2) times the limit
  // (below): within it at 0.21 (0.247), over it at 0.2 (0.235).
  EXPECT_EQ(NotConvergedProblem(ConvergedReport(), 0.21), "");
  EXPECT_NE(NotConvergedProblem(ConvergedReport(), 0.2), "");
}

// Stage 3's median is of the corners' residual DISTANCES, hypot(du, dv),
// and --max-rms-px limits an RMS over coordinates: for Gaussian residuals of
// sigma per coordinate the median distance is sigma sqrt(2 ln 2) = 1.1774
// sigma. Held to the limit itself, a stage 3 whose every corner had the
// noise of a 0.85 px RMS was refused while stages 1 and 2 accept 1 px; it
// is held to sqrt(2 ln 2) times the limit.
TEST(Convergence, StageThreesMedianDistanceIsHeldToTheLimitOfAnRmsOfItsCoordinates) {
  const double k = std::sqrt(2.0 * std::log(2.0));
  CalibrationReport r = ConvergedReport();
  r.system.refined_reprojection_rms_px = 0.95;            // within 1 px
  r.system.refined_median_corner_residual_px = 0.95 * k;  // Gaussian at 0.95 px
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.system.refined_median_corner_residual_px = k * (1 - 1e-9);  // at the boundary: within
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.system.refined_median_corner_residual_px = k * (1 + 1e-9);
  // Refused by its median alone: the message names the median and its own
  // limit, and says the rms is within (it read "rms 0.95 px ..., over
  // --max-rms-px 1", an rms within the limit said to be over it).
  const std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_TRUE(StartsWith(p,
                         "stage 3 did not converge: half its corners off by more than 1.177 px, over sqrt(2 ln 2) x "
                         "--max-rms-px = 1.177 px"))
      << p;
  EXPECT_NE(p.find("its rms 0.95 px is within 1 px"), std::string::npos) << p;
  EXPECT_EQ(p.find("over --max-rms-px"), std::string::npos) << p;
}

TEST(Convergence, StageOneNamesEachCameraOverTheLimitAndItsWorstView) {
  CalibrationReport r = ConvergedReport();
  r.intrinsics[1].rms_px = 25.475;
  r.intrinsics[1].num_outliers = 23;
  r.intrinsics[1].worst_views[0].rms_px = 40.5;
  r.intrinsics[3].rms_px = std::numeric_limits<double>::quiet_NaN();  // a solve that failed outright
  r.stereo[0].rms_px = 30;                                            // follows from camera 1: not named
  const std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_TRUE(StartsWith(p,
                         "stage 1 did not converge: camera 1 (cam1) at rms 25.48 px with 23 outlier corner(s), worst "
                         "view capture 007 at 40.5 px, camera 3 (cam3) at rms nan px"))
      << p;
  EXPECT_NE(p.find("over --max-rms-px 1 "), std::string::npos) << p;
  EXPECT_NE(p.find("--focal"), std::string::npos) << p;
  EXPECT_EQ(p.find("camera 0"), std::string::npos) << p;
  EXPECT_EQ(p.find("module0"), std::string::npos) << p;
}

TEST(Convergence, StageTwoIsNamedWhenEveryCameraConverged) {
  CalibrationReport r = ConvergedReport();
  r.stereo[1].rms_px = 3.5;
  r.stereo[1].num_outliers = 2;
  r.system.refined_median_corner_residual_px = 4;  // follows from module 1: not named
  const std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_TRUE(StartsWith(p, "stage 2 did not converge: module1 at rms 3.5 px with 2 outlier corner(s), over")) << p;
  EXPECT_NE(p.find("not taken at the same moment"), std::string::npos) << p;
  EXPECT_EQ(p.find("module0"), std::string::npos) << p;
}

// Stage 3 is judged by its RMS, as stages 1 and 2 are, and by its median
// corner residual: the median alone let one capture whose module 1 images
// were another capture's pass (rms 24.4 px, median 0.15 px; its S 2.2 mm off).
TEST(Convergence, StageThreeIsJudgedByItsRmsAndItsMedianCornerResidual) {
  CalibrationReport r = ConvergedReport();
  r.capture_names = {{2, "002"}, {3, "003"}, {5, "005"}, {7, "007"}, {9, "009"}};
  // Worst first (SystemReport::refined_capture_rms); median 0.2 px.
  r.system.refined_capture_rms = {{3, 40.0, 100}, {7, 0.25, 90}, {2, 0.2, 80}, {5, 0.15, 70}, {9, 0.1, 60}};
  r.system.refined_reprojection_rms_px = 20.0;  // one capture far off: the median alone passed it
  std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_TRUE(StartsWith(p,
                         "stage 3 did not converge: rms 20 px (half its corners off by more than 0.24 px), over "
                         "--max-rms-px 1; its worst capture 003 at rms 40 px over 100 corners (1 of 5 captures over "
                         "the limit), the median capture at rms 0.2 px: "
                         "the worst 200 times it ("))
      << p;
  EXPECT_NE(p.find("not taken at the same moment"), std::string::npos) << p;
  EXPECT_NE(p.find("back face"), std::string::npos) << p;
  // Several over the limit: each named, worst first, at most 3.
  r.system.refined_capture_rms = {{3, 40.0, 100}, {7, 5.0, 90}, {2, 2.0, 80}, {5, 1.5, 70}, {9, 0.5, 60}};
  p = NotConvergedProblem(r, 1.0);
  EXPECT_NE(p.find("; its worst captures 003 at rms 40 px over 100 corners, 007 at rms 5 px over 90 corners, 002 at "
                   "rms 2 px over 80 corners (4 of 5 captures over the limit), the median capture at rms 2 px: the "
                   "worst 20 times it"),
            std::string::npos)
      << p;
  // An even count's median is the mean of the middle two, (0.1 + 0.3) / 2.
  r.system.refined_capture_rms = {{3, 40.0, 100}, {7, 0.3, 90}, {2, 0.1, 80}, {5, 0.05, 70}};
  p = NotConvergedProblem(r, 1.0);
  EXPECT_NE(p.find("(1 of 4 captures over the limit), the median capture at rms 0.2 px: the worst 200 times it"),
            std::string::npos)
      << p;
  r.system.refined_reprojection_rms_px = 0.9;  // under the limit, but half the corners over it
  r.system.refined_median_corner_residual_px = 1.5;
  EXPECT_TRUE(StartsWith(NotConvergedProblem(r, 1.0),
                         "stage 3 did not converge: half its corners off by more than 1.5 px, over sqrt(2 ln 2) x "
                         "--max-rms-px = 1.177 px"))
      << NotConvergedProblem(r, 1.0);
  r.system.refined_median_corner_residual_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(NotConvergedProblem(r, 1.0), "");
  r.system.refined_median_corner_residual_px = 0.24;
  r.system.refined_reprojection_rms_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(NotConvergedProblem(r, 1.0), "");
  r.system.refined_reprojection_rms_px = 0.9;
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.system.refined_reprojection_rms_px = 20;
  r.num_modules = 1;  // no stage 3: its figures are not read
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.num_modules = 2;  // stage 2 not run (after a stage 1 over the limit): nor are they
  r.stereo.clear();
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// Stage 3's cameras with stage 2's noise on each (stage 2's per-camera rms)
// and their stage 3 residual distances drawn as that noise gives them
// (Rayleigh: the median 1.1774 sigma, the 90th percentile 2.1460 sigma).
CalibrationReport WithCameraResiduals(double stage2_sigma_px, double stage3_sigma_px) {
  CalibrationReport r = ConvergedReport();
  for (StereoReport& m : r.stereo) {
    m.rms_px = stage2_sigma_px;
    m.left.camera = 2 * m.module, m.right.camera = 2 * m.module + 1;
    m.left.camera_name = "cam" + std::to_string(m.left.camera);
    m.right.camera_name = "cam" + std::to_string(m.right.camera);
    m.left.rms_px = m.right.rms_px = stage2_sigma_px;
  }
  for (int c = 0; c < 4; ++c)
    r.system.refined_camera_residuals.push_back(
        {c, 1000, stage3_sigma_px, kRayleighMedian * stage3_sigma_px, kRayleighP90 * stage3_sigma_px});
  r.system.refined_reprojection_rms_px = stage3_sigma_px;
  r.system.refined_median_corner_residual_px = kRayleighMedian * stage3_sigma_px;
  return r;
}

// Each camera of stage 3 is held to the noise stage 2 measured on it: its
// median and 90th percentile distance against the Rayleigh quantiles of
// sqrt(sigma^2 + e^2), e = max(sigma, a tenth of the limit). A module moved
// 1 mm between captures read stage 3 at 0.88 px (median 1.02 px), within
// the 1 px limit, over stage 2's 0.196 px (CalibrateConvergence.
// AModuleThatMovedOneMillimetreIsRefusedAgainstStageTwosNoise).
TEST(Convergence, StageThreesCamerasAreHeldToTheirStageTwoNoise) {
  // Honest: stage 3 at stage 2's noise, at any level within the limit.
  for (double sigma : {0.02, 0.2, 0.85}) EXPECT_EQ(NotConvergedProblem(WithCameraResiduals(sigma, sigma), 1.0), "");
  // The moved module's figures: 0.88 px against 0.196 px of noise.
  CalibrationReport r = WithCameraResiduals(0.196, 0.88);
  std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_TRUE(StartsWith(p,
                         "stage 3 did not converge: its corners are off by more than the noise stage 2 measured on "
                         "them: camera 0 (cam0 of module0) at a median distance of 1.036 px and a 90th percentile of "
                         "1.888 px over 1000 corners, against 0.3264 px and 0.5948 px for its stage 2 noise of "
                         "0.196 px; camera 1 (cam1 of module0) at"))
      << p;
  EXPECT_NE(p.find("; and 2 other camera(s) (the limits: "), std::string::npos) << p;
  EXPECT_NE(p.find("a module that moved between captures"), std::string::npos) << p;
  // The boundary: sqrt(2) sigma is the spread allowed, by the median and by
  // the 90th percentile alike; the worst camera is named first.
  const double allowed = std::sqrt(2.0) * 0.196;
  r = WithCameraResiduals(0.196, allowed * (1 - 1e-9));
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.system.refined_camera_residuals[3].median_px = kRayleighMedian * allowed * (1 + 1e-9);
  p = NotConvergedProblem(r, 1.0);
  EXPECT_NE(p.find("them: camera 3 (cam3 of module1) at a median distance of 0.3264 px"), std::string::npos) << p;
  EXPECT_EQ(p.find("camera 0"), std::string::npos) << p;
  r = WithCameraResiduals(0.196, allowed * (1 - 1e-9));
  r.system.refined_camera_residuals[2].p90_px = kRayleighP90 * allowed * (1 + 1e-9);
  EXPECT_NE(NotConvergedProblem(r, 1.0).find("them: camera 2 (cam2 of module1)"), std::string::npos);
  // The floor: below a tenth of the limit, the excess is not refused
  // whatever the noise: 0.02 px of noise may reach hypot(0.02, 0.1) px.
  const double floor_spread = std::hypot(0.02, 0.1);
  EXPECT_EQ(NotConvergedProblem(WithCameraResiduals(0.02, floor_spread * (1 - 1e-9)), 1.0), "");
  EXPECT_NE(NotConvergedProblem(WithCameraResiduals(0.02, floor_spread * (1 + 1e-9)), 1.0), "");
  // Where the floor sets the limits, the refusal says so: from 0.02 px of
  // noise and as much again they would be 3.6 times smaller than quoted.
  p = NotConvergedProblem(WithCameraResiduals(0.02, floor_spread * (1 + 1e-9)), 1.0);
  EXPECT_NE(p.find("against 0.1201 px and 0.2188 px for its stage 2 noise of 0.02 px and the floor of 0.1 px "
                   "(0.1 x --max-rms-px); camera 1"),
            std::string::npos)
      << p;
  EXPECT_NE(p.find("(the limits: the median and 90th percentile of corner distances whose coordinates have that "
                   "noise and as much again, or that noise and the floor where the noise is less than the floor; "),
            std::string::npos)
      << p;
  // Where the noise sets them (0.196 px against a floor of 0.1 px), no floor is named.
  p = NotConvergedProblem(WithCameraResiduals(0.196, 0.88), 1.0);
  EXPECT_EQ(p.find("and the floor of"), std::string::npos) << p;
  // ... and scales with the limit: at 1.5 px, hypot(0.02, 0.15) px.
  EXPECT_EQ(NotConvergedProblem(WithCameraResiduals(0.02, std::hypot(0.02, 0.15) * (1 - 1e-9)), 1.5), "");
  EXPECT_NE(NotConvergedProblem(WithCameraResiduals(0.02, std::hypot(0.02, 0.15) * (1 + 1e-9)), 1.5), "");
  // A camera's own stage 2 rms, not its module's, where given.
  r = WithCameraResiduals(0.196, 0.25);
  r.stereo[1].right.rms_px = 0.1;
  EXPECT_TRUE(StartsWith(NotConvergedProblem(r, 1.0),
                         "stage 3 did not converge: its corners are off by more than the noise stage 2 measured on "
                         "them: camera 3 (cam3 of module1)"))
      << NotConvergedProblem(r, 1.0);
  // The limit's rules come first: their message names the rms or median.
  EXPECT_TRUE(StartsWith(NotConvergedProblem(WithCameraResiduals(0.196, 1.5), 1.0), "stage 3 did not converge: rms "));
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// Stage 3's Horn-only solve is warned of for what happened to it: stopped
// short (its rms where it stopped), converged with residuals that could not
// be evaluated (its rms NaN: it "did not converge" and its NaN "is where it
// stopped" before), or both.
TEST(Convergence, AHornOnlySolveIsWarnedOfForWhatHappened) {
  const std::string head =
      "stage 3's Horn-only solve (S and the stereo pairs held at Horn's and stage 2's, the board poses solved) ";
  const std::string rms = ": its rms (the report's horn_only, the rig file's rig_horn_only_rms_px) is ";
  const std::string stopped = "Ceres ended at NO_CONVERGENCE after 1 iteration (Maximum number of iterations reached)";
  const std::string unread = "its residuals could not be evaluated (a projection failed)";
  SystemReport s;
  s.horn_reprojection_rms_px = 0.2;
  EXPECT_EQ(HornOnlyWarning(s), "");
  s.horn_only_stopped_short = true;
  s.horn_only_solver_problem = stopped;
  EXPECT_EQ(HornOnlyWarning(s), head + "did not converge: " + stopped + rms +
                                    "where it stopped, not what Horn's S gives; the full adjustment started from "
                                    "there and is judged on its own (--max-iterations raises the limit of both)");
  s.horn_reprojection_rms_px = std::numeric_limits<double>::quiet_NaN();
  s.horn_only_solver_problem = stopped + "; " + unread;
  EXPECT_EQ(HornOnlyWarning(s), head + "did not converge: " + stopped + "; " + unread + rms +
                                    "not a number; the full adjustment started from there and is judged on its own "
                                    "(--max-iterations raises the limit of both)");
  s.horn_only_stopped_short = false;
  s.horn_only_solver_problem = unread;
  EXPECT_EQ(HornOnlyWarning(s), head + "converged, but " + unread + rms +
                                    "not a number; the full adjustment started from its solution and is judged on "
                                    "its own");
}

}  // namespace
}  // namespace stereorig
