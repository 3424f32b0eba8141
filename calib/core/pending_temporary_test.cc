// A termination signal during a write removes the temporary file; the
// process still dies of the signal. Run in a forked child, the parent looks.
#include "calib/core/pending_temporary.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>

#include "calib/core/atomic_file.h"
#include "calib/core/input_error_testing.h"

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
  const pid_t child = fork();
  if (child == 0) {
    if (own_handler) std::signal(signal, own_handler);
    AtomicOutput out(dir + "/cloud.ply");
    FILE* f = std::fopen(out.temp_path().c_str(), "wb");
    if (!f || std::fputs("half a cloud", f) < 0 || std::fclose(f) != 0) _exit(3);
    raise(signal);
    _exit(4);  // not reached: the signal ends the child
  }
  int status = 0;
  waitpid(child, &status, 0);
  return status;
}

TEST(PendingTemporary, ATerminationSignalMidWriteRemovesTheTemporaryFile) {
  for (const int signal : {SIGTERM, SIGINT, SIGHUP}) {
    const std::string dir = testing::ScratchFolder("pending_temporary_" + std::to_string(signal));
    const int status = StatusOfAChildSignalledMidWrite(dir, signal, nullptr);
    ASSERT_TRUE(WIFSIGNALED(status)) << "child exit status " << WEXITSTATUS(status);
    EXPECT_EQ(WTERMSIG(status), signal);  // it still dies of the signal
    EXPECT_EQ(FileCount(dir), 0) << "the temporary file was left";
  }
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

}  // namespace
}  // namespace stereorig
