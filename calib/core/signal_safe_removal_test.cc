#include "calib/core/signal_safe_removal.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

// dir/tree: files, nested and empty folders, and links out of it (to a
// folder, to a file) and to nowhere; dir/outside: what the links point to.
std::string MakeTreeWithLinksOut(const std::string& dir) {
  const std::string tree = dir + "/tree";
  fs::create_directories(tree + "/calibration/000");
  fs::create_directories(tree + "/truth/scenes/cup");
  fs::create_directories(tree + "/empty");
  fs::create_directories(dir + "/outside");
  for (const char* file : {"/spec.yaml", "/calibration/000/cam0.png", "/truth/scenes/cup/surface.ply"})
    std::ofstream(tree + file) << "x";
  std::ofstream(dir + "/outside/keep.txt") << "keep";
  fs::create_directory_symlink(dir + "/outside", tree + "/truth/link_to_folder");
  fs::create_symlink(dir + "/outside/keep.txt", tree + "/link_to_file");
  fs::create_symlink(dir + "/nowhere", tree + "/calibration/dangling");
  return tree;
}

TEST(RemoveTreeSignalSafe, RemovesAFolderAndAllItHoldsButNotWhatItsLinksPointTo) {
  const std::string dir = testing::ScratchFolder("remove_tree");
  const std::string tree = MakeTreeWithLinksOut(dir);
  EXPECT_TRUE(RemoveTreeSignalSafe(tree.c_str()));
  EXPECT_FALSE(fs::exists(fs::symlink_status(tree)));
  EXPECT_TRUE(fs::exists(dir + "/outside/keep.txt"));
  EXPECT_TRUE(RemoveTreeSignalSafe(tree.c_str())) << "not there: gone";
}

// A file, or a link to a folder, given as the path is removed itself.
TEST(RemoveTreeSignalSafe, AFileOrALinkIsRemovedItself) {
  const std::string dir = testing::ScratchFolder("remove_tree_link");
  fs::create_directories(dir + "/folder/inside");
  fs::create_directory_symlink(dir + "/folder", dir + "/link");
  std::ofstream(dir + "/file") << "x";
  EXPECT_TRUE(RemoveTreeSignalSafe((dir + "/link").c_str()));
  EXPECT_TRUE(RemoveTreeSignalSafe((dir + "/file").c_str()));
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir + "/link")));
  EXPECT_FALSE(fs::exists(dir + "/file"));
  EXPECT_TRUE(fs::is_directory(dir + "/folder/inside"));
}

// Folders are entered kMaxRemovalDepth levels deep, no deeper: a deeper
// chain is left, the folders that hold it too.
TEST(RemoveTreeSignalSafe, FoldersDeeperThanTheLimitAreLeft) {
  const std::string dir = testing::ScratchFolder("remove_tree_deep");
  for (const int levels : {kMaxRemovalDepth, kMaxRemovalDepth + 1}) {
    std::string deepest = dir + "/top";
    for (int level = 2; level <= levels; ++level) deepest += "/d";
    fs::create_directories(deepest);
    std::ofstream(deepest + "/file") << "x";
    EXPECT_EQ(RemoveTreeSignalSafe((dir + "/top").c_str()), levels <= kMaxRemovalDepth) << levels;
    EXPECT_EQ(fs::exists(deepest + "/file"), levels > kMaxRemovalDepth) << levels;
  }
}

}  // namespace
}  // namespace stereorig
