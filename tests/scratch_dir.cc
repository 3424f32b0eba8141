// Linked into every test binary by stereorig_add_test: before main, points
// gtest's TempDir() (TEST_TMPDIR) and std::filesystem::temp_directory_path()
// (TMPDIR) at this binary's own scratch folder inside the build tree, so two
// builds, or two test binaries run in parallel, never share a file in /tmp.
// A caller that already set either variable keeps it.
#include <cstdlib>
#include <filesystem>

namespace {

const bool kScratchDirSet = [] {
  std::filesystem::create_directories(STEREORIG_TEST_SCRATCH_DIR);
  setenv("TEST_TMPDIR", STEREORIG_TEST_SCRATCH_DIR "/", /*overwrite=*/0);
  setenv("TMPDIR", STEREORIG_TEST_SCRATCH_DIR, /*overwrite=*/0);
  return true;
}();

}  // namespace
