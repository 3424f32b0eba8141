// Linked into every test binary by stereorig_add_test: before main, points
// gtest's TempDir() (TEST_TMPDIR) and std::filesystem::temp_directory_path()
// (TMPDIR) at a scratch folder of this process's own inside the build tree,
// so two builds, two test binaries, or two test cases of one binary that
// ctest -j runs as separate processes (gtest_discover_tests) never share a
// file: a suite's SetUpTestSuite that clears and refills its folder would
// otherwise pull the files from under a sibling case. The folder is removed
// when every test of the process passed, and kept for a look when one failed.
// A caller that already set either variable keeps it; only this process's
// own folder is ever removed.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace {

const std::string kProcessScratchDir = std::string(STEREORIG_TEST_SCRATCH_DIR) + "/pid" + std::to_string(getpid());

class RemoveScratchWhenPassed : public ::testing::Environment {
 public:
  void TearDown() override {
    if (!::testing::UnitTest::GetInstance()->Passed()) return;
    std::error_code ignored;
    std::filesystem::remove_all(kProcessScratchDir, ignored);
  }
};

const bool kScratchDirSet = [] {
  std::filesystem::create_directories(kProcessScratchDir);
  setenv("TEST_TMPDIR", (kProcessScratchDir + "/").c_str(), /*overwrite=*/0);
  setenv("TMPDIR", kProcessScratchDir.c_str(), /*overwrite=*/0);
  ::testing::AddGlobalTestEnvironment(new RemoveScratchWhenPassed);  // gtest owns it
  // A run that runs no test (ctest's --gtest_list_tests discovery) leaves the
  // folder empty: remove() takes only an empty folder.
  std::atexit([] {
    std::error_code ignored;
    std::filesystem::remove(kProcessScratchDir, ignored);
  });
  return true;
}();

}  // namespace
