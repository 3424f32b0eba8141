#include "calib/core/folder_to_create.h"

#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <stdexcept>

#include "calib/core/atomic_file.h"
#include "calib/core/input_error_testing.h"
#include "calib/core/signal_testing.h"

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

// A termination signal while the object lives (Ctrl-C mid-run) removes the
// folders it made, as a failure does, once the pending temporary files in
// them are gone (pending_temporary.h); they used to stay, empty. Only while
// empty (x/y holds a file: it and x stay), and only those it made: `dir`,
// and `dir`/p, made by another process (here the child itself) between the
// claim and Create, stay, though empty.
TEST(FolderToCreate, ATerminationSignalRemovesWhatItCreatedWhileEmpty) {
  for (const int signal : {SIGTERM, SIGINT, SIGHUP}) {
    const std::string dir = Scratch("signal_" + std::to_string(signal));
    const int status = testing::StatusOfAChild([&] {
      FolderToCreate outputs(dir + "/a/b/c", "the test folder");
      FolderToCreate kept(dir + "/x/y", "the test folder");
      FolderToCreate theirs(dir + "/p/q", "the test folder");
      fs::create_directory(dir + "/p");  // another process's, after the claim
      outputs.Create();
      kept.Create();
      theirs.Create();
      std::ofstream(dir + "/x/y/written.txt") << "written before the signal\n";
      AtomicOutput out(dir + "/a/b/c/cloud.ply");  // a pending temporary file in the folder
      std::ofstream(out.temp_path()) << "half a cloud";
      if (!fs::exists(out.temp_path()) || !fs::is_directory(dir + "/p/q")) _exit(3);
      raise(signal);
    });
    ASSERT_TRUE(testing::DiedOf(status, signal));
    EXPECT_FALSE(fs::exists(dir + "/a")) << "the folders it made were left";
    EXPECT_TRUE(fs::exists(dir + "/x/y/written.txt"));
    EXPECT_FALSE(fs::exists(dir + "/p/q"));
    EXPECT_TRUE(fs::is_directory(dir + "/p")) << "another's folder was removed";
    EXPECT_TRUE(fs::is_directory(dir));
  }
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
