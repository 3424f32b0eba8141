#include "tests/made_once.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <system_error>

namespace stereorig::testing {

std::string MadeOnce(const std::string& name, const std::function<void(const std::string& dir)>& make) {
  namespace fs = std::filesystem;
  const fs::path scratch(STEREORIG_TEST_SCRATCH_DIR);
  const std::string build =
      "made_once-" + std::to_string(static_cast<unsigned long long>(
                         fs::last_write_time(fs::read_symlink("/proc/self/exe")).time_since_epoch().count()));
  const fs::path shared = scratch / build / name;
  if (fs::is_directory(shared)) return shared.string();
  std::error_code ignored;
  for (const fs::directory_entry& e : fs::directory_iterator(scratch, ignored)) {
    const std::string folder = e.path().filename().string();
    if (folder.rfind("made_once-", 0) == 0 && folder != build) fs::remove_all(e.path(), ignored);
  }
  fs::create_directories(scratch / build);
  const fs::path making = scratch / build / (name + ".making-" + std::to_string(getpid()));
  fs::remove_all(making);
  make(making.string());
  if (::testing::Test::HasFailure()) return making.string();
  std::error_code raced;  // another case renamed its own into place first
  fs::rename(making, shared, raced);
  if (raced) fs::remove_all(making, ignored);
  return shared.string();
}

}  // namespace stereorig::testing
