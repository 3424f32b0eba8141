#include "apps/demo_out.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

// An earlier dataset as simulate writes it, as far as CheckReplaceableOut
// reads it: spec.yaml and truth/simulation.yaml of its format.
void EarlierDataset(const std::string& dir) {
  fs::create_directories(dir + "/truth");
  std::ofstream(dir + "/spec.yaml") << "format: stereorig-sim-spec\n";
  std::ofstream(dir + "/truth/simulation.yaml") << "format: stereorig-sim-info\n";
}

// `demo --out` over a folder of the user's replaced its files of the
// demo's names and wrote beside the rest (a mine.txt kept among the demo's
// outputs); simulate refuses such a folder. A missing or empty one, or an
// earlier demo's, is written into.
TEST(CheckDemoOut, WritesOnlyIntoAnEmptyFolderOrAnEarlierDemos) {
  const std::string dir = testing::ScratchFolder("demo_out");
  EXPECT_NO_THROW(CheckDemoOut(dir + "/missing"));
  fs::create_directories(dir + "/empty");
  EXPECT_NO_THROW(CheckDemoOut(dir + "/empty"));

  const std::string earlier = dir + "/earlier";
  EarlierDataset(earlier + "/dataset");
  for (const char* name : {"rig.yaml", "calibration.json", "cam0.cameramodel", "cam12.cameramodel", "cup_active.ply",
                           "check-history.sqlite", "check-history.sqlite-journal", "verify_ballbar.json"})
    std::ofstream(earlier + "/" + name) << "written by the demo\n";
  fs::create_directories(earlier + "/night_ok");
  EXPECT_NO_THROW(CheckDemoOut(earlier));

  std::ofstream(earlier + "/mine.txt") << "the user's\n";
  EXPECT_EQ(testing::InputErrorMessage([&] { CheckDemoOut(earlier); }),
            earlier +
                ": holds mine.txt, which the demo does not write; refusing to write into it (move it out, or choose "
                "another --out)");
  fs::remove(earlier + "/mine.txt");
  std::ofstream(earlier + "/cam01.cameramodel") << "not a name calibrate writes\n";
  EXPECT_NE(testing::InputErrorMessage([&] { CheckDemoOut(earlier); }).find("holds cam01.cameramodel"),
            std::string::npos);
  fs::remove(earlier + "/cam01.cameramodel");

  // The demo's names without its dataset: a user's own rig.yaml.
  fs::create_directories(dir + "/user");
  std::ofstream(dir + "/user/rig.yaml") << "the user's rig\n";
  EXPECT_EQ(testing::InputErrorMessage([&] { CheckDemoOut(dir + "/user"); }),
            dir +
                "/user: is not an earlier demo's folder (no dataset/), yet holds files of the names the demo writes; "
                "refusing to replace them (choose another --out)");

  // dataset/ that simulate would not replace: refused now, not at step 1.
  std::ofstream(earlier + "/dataset/notes.txt") << "the user's\n";
  EXPECT_NE(testing::InputErrorMessage([&] {
              CheckDemoOut(earlier);
            }).find(earlier + "/dataset: holds notes.txt, which the simulator does not write"),
            std::string::npos);
}

}  // namespace
}  // namespace stereorig
