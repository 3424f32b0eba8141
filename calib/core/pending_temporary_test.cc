// A termination signal during a write removes the temporary file; the
// process still dies of the signal. Run in a forked child, the parent looks.
#include "calib/core/pending_temporary.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "calib/core/atomic_file.h"
#include "calib/core/input_error_testing.h"
#include "calib/core/signal_testing.h"

namespace stereorig {
namespace {

int FileCount(const std::string& dir) {
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) ++n, (void)entry;
  return n;
}

// In a child: an atomic output whose temporary file is written, then
// `signal` raised before the rename. The child's wait status.
int StatusOfAChildSignalledMidWrite(const std::string& dir, int signal, void (*own_handler)(int)) {
  return testing::StatusOfAChild([&] {
    if (own_handler) std::signal(signal, own_handler);
    AtomicOutput out(dir + "/cloud.ply");
    FILE* f = std::fopen(out.temp_path().c_str(), "wb");
    if (!f || std::fputs("half a cloud", f) < 0 || std::fclose(f) != 0) _exit(3);
    raise(signal);
  });
}

TEST(PendingTemporary, ATerminationSignalMidWriteRemovesTheTemporaryFile) {
  for (const int signal : {SIGTERM, SIGINT, SIGHUP, SIGPIPE}) {
    const std::string dir = testing::ScratchFolder("pending_temporary_" + std::to_string(signal));
    const int status = StatusOfAChildSignalledMidWrite(dir, signal, nullptr);
    ASSERT_TRUE(testing::DiedOf(status, signal));  // it still dies of the signal
    EXPECT_EQ(FileCount(dir), 0) << "the temporary file was left";
  }
}

// Many at once: `score --diagnose` holds four images per scene and module
// until its report is written (AtomicOutputSet), 132 on the ring of three
// modules with 11 scenes, beyond the 128 slots there were: the rest stayed
// as hidden .tmp-* files. 300 temporaries, all removed.
TEST(PendingTemporary, ATerminationSignalRemovesHundredsOfPendingFiles) {
  const std::string dir = testing::ScratchFolder("pending_temporary_many");
  constexpr int kFiles = 300;
  const int status = testing::StatusOfAChild([&] {
    std::vector<std::unique_ptr<AtomicOutput>> outs;
    for (int i = 0; i < kFiles; ++i) {
      outs.push_back(std::make_unique<AtomicOutput>(dir + "/image" + std::to_string(i) + ".png"));
      std::ofstream(outs.back()->temp_path()) << "an image";
    }
    if (FileCount(dir) != kFiles) _exit(3);  // every temporary written
    raise(SIGTERM);
  });
  ASSERT_TRUE(testing::DiedOf(status, SIGTERM)) << status;
  EXPECT_EQ(FileCount(dir), 0) << "temporary files were left";
}

// A program's own handler is left alone (it decides what a signal does);
// here it exits at once, so the temporary file stays: the control that
// shows the file was there to remove.
extern "C" void ExitSeven(int) { _exit(7); }
TEST(PendingTemporary, AProgramsOwnHandlerIsKept) {
  const std::string dir = testing::ScratchFolder("pending_temporary_own_handler");
  const int status = StatusOfAChildSignalledMidWrite(dir, SIGTERM, ExitSeven);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 7);
  EXPECT_EQ(FileCount(dir), 1);
}

// A folder's tree goes too (simulate's temporary dataset): its files and
// folders, and a link in it, but not the folder outside the tree that the
// link points to. The child fills the folder once it is registered, as
// simulate does, then the signal comes.
TEST(PendingTemporary, ATerminationSignalRemovesAPendingFolderButNotWhatItsLinksPointTo) {
  for (const int signal : {SIGTERM, SIGINT, SIGHUP, SIGPIPE}) {
    const std::string dir = testing::ScratchFolder("pending_folder_" + std::to_string(signal));
    const std::string tree = dir + "/.ds.tmp-1";
    std::filesystem::create_directory(dir + "/outside");
    std::ofstream(dir + "/outside/keep.txt") << "keep";
    const int status = testing::StatusOfAChild([&] {
      PendingTemporary pending(tree, TemporaryKind::kFolder);
      std::error_code ec;
      std::filesystem::create_directories(tree + "/calibration/000", ec);
      std::filesystem::create_directories(tree + "/truth/scenes/cup", ec);
      for (const char* file : {"/spec.yaml", "/calibration/000/cam0.png", "/truth/scenes/cup/surface.ply"})
        std::ofstream(tree + file) << "x";
      std::filesystem::create_directory_symlink(dir + "/outside", tree + "/truth/outside", ec);
      if (ec) _exit(3);
      raise(signal);
    });
    ASSERT_TRUE(testing::DiedOf(status, signal));
    EXPECT_EQ(FileCount(dir), 1) << "the temporary folder was left";
    EXPECT_TRUE(std::filesystem::exists(dir + "/outside/keep.txt")) << "the link was followed";
  }
}

}  // namespace
}  // namespace stereorig
