#include "apps/reconstruct_batch.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "calib/core/input_error.h"

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

TEST(BatchOutputNames, AFolderGivenTwiceOrCollidingNamesAreBadInput) {
  EXPECT_THROW(BatchOutputNames({"/d/a", "/d/b", "/d/a/"}), InputError);
  EXPECT_THROW(BatchOutputNames({"/d/a_b", "/d/a/b"}), InputError);
  EXPECT_THROW(BatchOutputNames({"/"}), InputError);
}

}  // namespace
}  // namespace stereorig
