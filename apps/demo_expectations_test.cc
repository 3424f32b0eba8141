#include "apps/demo_expectations.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

// A check report with only the keys the demo reads (docs/verify-and-check.md,
// "The report"), written to `dir`.
std::string Report(const std::string& dir, const std::string& json) {
  const std::string path = dir + "/check_bumped.json";
  std::ofstream(path) << json;
  return path;
}

// The demo's bumped night passes only when the check names the bumped camera
// alone, as the README promises. Before, its exit code 1 was all it
// compared: any recalibrate passed, one naming camera 3 or a module only.
TEST(BumpedNightSurprise, PassesOnlyTheBumpedCameraNamedAlone) {
  const std::string dir = testing::ScratchFolder("demo_bumped_night");
  const std::string expected = ", expected recalibrate naming camera 1 alone";
  for (const auto& [flagged, surprise] :
       {std::pair{R"("recalibrate", "flagged_cameras": [1], "flagged_modules": [])", std::string()},
        {R"("recalibrate", "flagged_cameras": [3], "flagged_modules": [])",
         "its report names cameras [3] and modules []" + expected},
        {R"("recalibrate", "flagged_cameras": [], "flagged_modules": [0])",
         "its report names cameras [] and modules [0]" + expected},
        {R"("recalibrate", "flagged_cameras": [1, 2], "flagged_modules": [])",
         "its report names cameras [1,2] and modules []" + expected},
        {R"("ok", "flagged_cameras": [], "flagged_modules": [])", "its report says \"ok\"" + expected}})
    EXPECT_EQ(BumpedNightSurprise(Report(dir, std::string(R"({"verdict": )") + flagged + "}"), 1), surprise) << flagged;
}

// A report that is missing or not a check report is a surprise named by its
// path, not a pass.
TEST(BumpedNightSurprise, AReportThatCannotBeReadIsNamed) {
  const std::string dir = testing::ScratchFolder("demo_bumped_unreadable");
  EXPECT_EQ(BumpedNightSurprise(dir + "/missing.json", 1), "its report " + dir + "/missing.json cannot be read");
  const std::string truncated = Report(dir, R"({"verdict": "recalibrate", "flagged_cam)");
  EXPECT_EQ(BumpedNightSurprise(truncated, 1),
            "its report " + truncated + " is not a check report (verdict, flagged_cameras, flagged_modules)");
  const std::string other = Report(dir, R"({"verdict": "recalibrate"})");
  EXPECT_EQ(BumpedNightSurprise(other, 1),
            "its report " + other + " is not a check report (verdict, flagged_cameras, flagged_modules)");
}

std::string Executable(const std::string& path) {
  std::ofstream(path) << "#!/bin/sh\n";
  fs::permissions(path, fs::perms::owner_all);
  return path;
}

// The demo's `$ stereorig ...` lines are pasted into a shell: when the shell
// would not run this binary for `stereorig` (a fresh build/stereorig, none
// installed, or another one installed), one line says which binary they mean.
TEST(BinaryNote, NamesTheBinaryWhenPathHasAnotherOrNone) {
  const std::string dir = testing::ScratchFolder("demo_binary_note");
  fs::create_directories(dir + "/bin");
  fs::create_directories(dir + "/my build");
  const std::string installed = Executable(dir + "/bin/stereorig");
  const std::string built = Executable(dir + "/my build/stereorig");
  EXPECT_EQ(BinaryNote(installed, ("/nonexistent:" + dir + "/bin").c_str()), "");
  // Through a link on PATH it is the same binary.
  fs::create_directories(dir + "/links");
  fs::create_symlink(installed, dir + "/links/stereorig");
  EXPECT_EQ(BinaryNote(installed, (dir + "/links").c_str()), "");
  EXPECT_EQ(BinaryNote(built, (dir + "/bin").c_str()),
            "note: `$ stereorig` below means '" + built + "' (not " + installed + ", the stereorig on PATH)");
  const std::string none = "note: `$ stereorig` below means '" + built +
                           "' (no stereorig on PATH; `cmake --install build` puts it in /usr/local/bin)";
  EXPECT_EQ(BinaryNote(built, "/nonexistent"), none);
  EXPECT_EQ(BinaryNote(built, nullptr), none);
  // A file that is not executable is not what the shell runs.
  fs::permissions(installed, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(BinaryNote(installed, (dir + "/bin").c_str()),
            "note: `$ stereorig` below means " + installed +
                " (no stereorig on PATH; `cmake --install build` puts it in /usr/local/bin)");
}

}  // namespace
}  // namespace stereorig
