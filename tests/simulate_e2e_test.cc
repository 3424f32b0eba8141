// `stereorig simulate` end to end (label e2e): the whole default dataset in
// with the layout docs/simulator.md fixes (its render time is printed).
#include <gtest/gtest.h>

#include <chrono>

#include "tests/sim_cli_util.h"

namespace {

using namespace sim_cli;

// The default dataset: ~50 captures and five scenes.
TEST(SimulateCliE2e, DefaultDatasetRendersWithTheDocumentedLayout) {
  const std::string dir = ::testing::TempDir() + "/sim_default_dataset";
  const auto t0 = std::chrono::steady_clock::now();
  const Result r = RunCli("simulate --out " + dir + " --seed 1");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.code, 0) << r.err;
  std::printf("default dataset: %.1f s\n%s", seconds, r.out.c_str());
  // Wall time is printed, not asserted: these machines are shared and noisy,
  // so speed is a measurement (docs/simulator.md gives the CPU time), not a test.
  for (const char* f : {"spec.yaml", "target.yaml", "layout.yaml", "truth/rig.yaml", "truth/calibration_poses.yaml",
                        "calibration/049/cam3.png"}) {
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
  }
  for (const char* s : {"cup", "sphere", "ballbar", "plate", "tuber"}) {
    const std::string scene = std::string(s);
    for (const char* f : {"active/cam0.png", "passive/cam3.png"}) {
      EXPECT_TRUE(fs::exists(dir + "/scenes/" + scene + "/" + f)) << scene << f;
    }
    for (const char* f : {"object.yaml", "surface.ply", "depth_cam2.tiff", "id_cam1.png"}) {
      EXPECT_TRUE(fs::exists(dir + "/truth/scenes/" + scene + "/" + f)) << scene << f;
    }
  }
}

}  // namespace
