#include "calib/core/folder_to_create.h"

#include <gtest/gtest.h>

#include "calib/core/input_error_testing.h"

#include <fstream>
#include <stdexcept>

namespace stereorig {
namespace {

namespace fs = std::filesystem;

std::string Scratch(const std::string& name) { return testing::ScratchFolder("folder_to_create_" + name); }

// Create() makes the folder and the missing ones above it; an exception
// leaving the object's scope removes them all again while empty, but never
// the folder that was there when it was claimed.
TEST(FolderToCreate, AFailureRemovesWhatItCreatedAndNothingElse) {
  const std::string dir = Scratch("fail");
  try {
    FolderToCreate folder(dir + "/a/b/c", "the test folder");
    EXPECT_TRUE(folder.WillCreate(dir + "/a"));
    EXPECT_TRUE(folder.WillCreate(dir + "/a/b/c"));
    EXPECT_FALSE(folder.WillCreate(dir));
    folder.Create();
    ASSERT_TRUE(fs::is_directory(dir + "/a/b/c"));
    throw std::runtime_error("bad input found after the folder was made");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(dir + "/a"));
  EXPECT_TRUE(fs::is_directory(dir));
}

// A folder holding a file stays, and so do the folders above it; one that
// existed before is not removed even while empty; without a failure nothing
// is removed.
TEST(FolderToCreate, WhatHoldsAFileOrExistedBeforeStays) {
  const std::string dir = Scratch("stays");
  {
    FolderToCreate folder(dir + "/a/b", "the test folder");
    folder.Create();
    std::ofstream(dir + "/a/b/written.txt") << "written before the failure\n";
    folder.RemoveIfEmpty();
  }
  EXPECT_TRUE(fs::exists(dir + "/a/b/written.txt"));
  fs::create_directories(dir + "/existing");
  {
    FolderToCreate folder(dir + "/existing", "the test folder");
    EXPECT_FALSE(folder.WillCreate(dir + "/existing"));
    folder.Create();
    folder.RemoveIfEmpty();
  }
  EXPECT_TRUE(fs::is_directory(dir + "/existing"));
  {
    FolderToCreate folder(dir + "/ok", "the test folder");
    folder.Create();
  }
  EXPECT_TRUE(fs::is_directory(dir + "/ok"));
}

// Moved (as OutputPaths::ClaimFolder's result is), only the last owner
// removes.
TEST(FolderToCreate, AMovedFromObjectRemovesNothing) {
  const std::string dir = Scratch("moved");
  FolderToCreate kept;
  {
    FolderToCreate folder(dir + "/a", "the test folder");
    folder.Create();
    kept = std::move(folder);
    folder.RemoveIfEmpty();  // moved from: nothing to remove
  }
  EXPECT_TRUE(fs::is_directory(dir + "/a"));
  kept.RemoveIfEmpty();
  EXPECT_FALSE(fs::exists(dir + "/a"));
}

// No folder asked for: Create and RemoveIfEmpty do nothing.
TEST(FolderToCreate, NoFolderDoesNothing) {
  FolderToCreate none;
  EXPECT_FALSE(none.WillCreate(::testing::TempDir()));
  none.Create();
  none.RemoveIfEmpty();
}

}  // namespace
}  // namespace stereorig
