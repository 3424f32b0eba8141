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
  EXPECT_EQ(NotConvergedProblem(ConvergedReport(), 0.24), "");  // at the limit: within it
  EXPECT_NE(NotConvergedProblem(ConvergedReport(), 0.23), "");  // stage 3's median
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

// Stage 3 is judged by its median corner residual: its robust loss leaves a
// few corners out by design, which its RMS counts in full.
TEST(Convergence, StageThreeIsJudgedByItsMedianCornerResidual) {
  CalibrationReport r = ConvergedReport();
  r.system.refined_reprojection_rms_px = 2.25;  // a few corners far off: passes
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.system.refined_median_corner_residual_px = 1.5;
  const std::string p = NotConvergedProblem(r, 1.0);
  EXPECT_TRUE(StartsWith(p,
                         "stage 3 did not converge: half its corners are off by more than 1.5 px (rms 2.25 px), over "
                         "--max-rms-px 1 "))
      << p;
  EXPECT_NE(p.find("back face"), std::string::npos) << p;
  r.system.refined_median_corner_residual_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(NotConvergedProblem(r, 1.0), "");
  r.num_modules = 1;  // no stage 3: its figures are not read
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
  r.num_modules = 2;  // stage 2 not run (after a stage 1 over the limit): nor are they
  r.stereo.clear();
  EXPECT_EQ(NotConvergedProblem(r, 1.0), "");
}

}  // namespace
}  // namespace stereorig
