#include "apps/reconstruct_batch.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

using Names = std::vector<std::string>;

TEST(BatchOutputNames, KeepWhatDiffersAfterTheSharedFolders) {
  EXPECT_EQ(BatchOutputNames({"/line/caps/0001", "/line/caps/0002"}), (Names{"0001", "0002"}));
  EXPECT_EQ(BatchOutputNames({"/d/scenes/cup/active", "/d/scenes/sphere/active"}),
            (Names{"cup_active", "sphere_active"}));
  // Different depths; a trailing slash and a '..' are the same folder's path.
  EXPECT_EQ(BatchOutputNames({"/d/a/", "/d/x/../b/c"}), (Names{"a", "b_c"}));
  // One folder inside another: the outer keeps its own name.
  EXPECT_EQ(BatchOutputNames({"/d/a", "/d/a/b"}), (Names{"a", "a_b"}));
}

TEST(BatchOutputNames, ASingleCaptureIsNamedByItsFolder) {
  EXPECT_EQ(BatchOutputNames({"/line/caps/0001"}), (Names{"0001"}));
}

TEST(BatchOutputNames, RelativePathsAreTakenFromTheWorkingFolder) {
  const std::string cwd = std::filesystem::current_path().string();
  EXPECT_EQ(BatchOutputNames({"caps/1", cwd + "/caps/2"}), (Names{"1", "2"}));
}

// The InputError's message, or "" if none was thrown.
std::string ErrorOf(const std::vector<std::string>& dirs) {
  return testing::InputErrorMessage([&] { BatchOutputNames(dirs); });
}

TEST(BatchOutputNames, AFolderGivenTwiceOrCollidingNamesAreBadInput) {
  EXPECT_NE(ErrorOf({"/d/a", "/d/b", "/d/a/"}).find("/d/a/ is given twice (as /d/a)"), std::string::npos);
  EXPECT_NE(ErrorOf({"/d/a_b", "/d/a/b"}).find("would both write outputs named 'a_b'"), std::string::npos);
  EXPECT_NE(ErrorOf({"/"}).find("root"), std::string::npos);
}

}  // namespace
}  // namespace stereorig
