#include "calib/scoped_stderr_capture.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

namespace stereorig {
namespace {

bool IsNoise(std::string_view line) { return line.rfind("noise:", 0) == 0; }

// What a C library does: fprintf(stderr) and write(2) on fd 2.
void LibraryPrints() {
  std::fprintf(stderr, "noise: going again\n");
  std::fprintf(stderr, "kept: a real error\n");
  const std::string raw = "noise: by write(2)\nkept: by write(2)\n";
  ASSERT_EQ(write(STDERR_FILENO, raw.data(), raw.size()), static_cast<ssize_t>(raw.size()));
  std::cerr << "kept: by std::cerr\n";
}

TEST(ScopedStderrCapture, DropsThePickedLinesAndWritesBackTheRestUnchanged) {
  ::testing::internal::CaptureStderr();  // stands for the terminal: fd 2 as the scope found it
  std::fprintf(stderr, "before\n");
  {
    ScopedStderrCapture capture(IsNoise);
    LibraryPrints();
  }
  std::fprintf(stderr, "after\n");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(),
            "before\nkept: a real error\nkept: by write(2)\nkept: by std::cerr\nafter\n");
}

// Another thread's line meanwhile lands in the capture too (one fd 2 per
// process): it comes out unchanged at the scope's end, not lost.
TEST(ScopedStderrCapture, AnotherThreadsLineMeanwhileComesOutUnchanged) {
  ::testing::internal::CaptureStderr();
  {
    ScopedStderrCapture capture(IsNoise);
    std::thread other([] { std::fprintf(stderr, "kept: another thread's progress\n"); });
    other.join();
    std::fprintf(stderr, "noise: going again\n");
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "kept: another thread's progress\n");
}

// Held until the scope's end: nothing reaches fd 2 meanwhile, so a dropped
// line never shows, not even for a moment. fd 2 is a file of the test's here,
// whose size is read inside the scope.
TEST(ScopedStderrCapture, NothingReachesStderrWhileTheScopeRuns) {
  std::FILE* outer = std::tmpfile();
  ASSERT_NE(outer, nullptr);
  std::fflush(stderr);
  const int terminal_fd = dup(STDERR_FILENO);
  ASSERT_GE(dup2(fileno(outer), STDERR_FILENO), 0);
  off_t size_during = -1;
  {
    ScopedStderrCapture capture(IsNoise);
    LibraryPrints();
    struct stat st {};
    if (fstat(fileno(outer), &st) == 0) size_during = st.st_size;
  }
  std::fflush(stderr);
  struct stat st {};
  fstat(fileno(outer), &st);
  dup2(terminal_fd, STDERR_FILENO);
  close(terminal_fd);
  std::fclose(outer);
  EXPECT_EQ(size_during, 0);
  EXPECT_EQ(st.st_size,
            static_cast<off_t>(std::string("kept: a real error\nkept: by write(2)\nkept: by std::cerr\n").size()));
}

// Nested in one thread, each scope ends where it began: the inner one sees
// its own lines only, and gives the outer one's file back as fd 2.
TEST(ScopedStderrCapture, NestedScopesEachSeeTheirOwnLines) {
  ::testing::internal::CaptureStderr();
  std::string inner_saw;
  {
    ScopedStderrCapture outer(IsNoise);
    std::fprintf(stderr, "kept: outer\n");
    {
      ScopedStderrCapture inner([&](std::string_view line) {
        inner_saw += std::string(line) + "|";
        return false;
      });
      std::fprintf(stderr, "noise: inner\n");
    }
    std::fprintf(stderr, "kept: outer again\n");
  }
  EXPECT_EQ(inner_saw, "noise: inner|");
  // The inner kept its line; the outer dropped it as noise.
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "kept: outer\nkept: outer again\n");
}

// A last line without its '\n' comes back as it was; an exception through the
// scope still gives fd 2 back.
TEST(ScopedStderrCapture, GivesStderrBackOnAnExceptionAndKeepsAnUnfinishedLine) {
  ::testing::internal::CaptureStderr();
  try {
    ScopedStderrCapture capture(IsNoise);
    std::fprintf(stderr, "noise: x\nkept: no newline");
    throw std::runtime_error("solve failed");
  } catch (const std::runtime_error&) {
  }
  std::fprintf(stderr, "|after\n");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "kept: no newline|after\n");
}

struct ChildEnd {
  std::string err;  // all the child wrote on fd 2
  int status = 0;   // as waitpid gives it
};

// Runs `body` in a forked child whose fd 2 is a pipe read here, as a
// terminal would see it: the child ends inside `body` (exit, abort, a
// signal), so whatever its stderr shows was written before it went.
ChildEnd RunChild(const std::function<void()>& body) {
  ChildEnd end;
  int fds[2];
  if (pipe(fds) != 0) return end;
  std::fflush(nullptr);  // nothing of ours written twice
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    dup2(fds[1], STDERR_FILENO);
    close(fds[1]);
    body();
    _exit(99);  // body did not end the child
  }
  close(fds[1]);
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    end.err.append(buf, static_cast<size_t>(n));
  }
  close(fds[0]);
  waitpid(pid, &end.status, 0);
  return end;
}

// A library that ends the process inside the scope (libdogleg calls exit(),
// libmrcal asserts) or a Ctrl-C meanwhile: the held lines are what says why,
// so they come out, all of them (no filter runs there), and the process ends
// as it would have without the scope.
void PrintsThenEnds(const std::function<void()>& end) {
  ScopedStderrCapture capture(IsNoise);
  std::fprintf(stderr, "noise: going again\n");
  std::fprintf(stderr, "kept: ASSERTION FAILED: isfinite(ctx->lambda) is not true\n");
  end();
}

constexpr char kHeld[] = "noise: going again\nkept: ASSERTION FAILED: isfinite(ctx->lambda) is not true\n";

TEST(ScopedStderrCapture, ExitInsideTheScopeWritesTheHeldLinesAndKeepsTheExitCode) {
  const ChildEnd end = RunChild([] { PrintsThenEnds([] { std::exit(3); }); });
  EXPECT_EQ(end.err, kHeld);
  ASSERT_TRUE(WIFEXITED(end.status)) << end.status;
  EXPECT_EQ(WEXITSTATUS(end.status), 3);
}

TEST(ScopedStderrCapture, AbortInsideTheScopeWritesTheHeldLinesAndStillAborts) {
  const ChildEnd end = RunChild([] { PrintsThenEnds([] { std::abort(); }); });
  EXPECT_EQ(end.err, kHeld);
  ASSERT_TRUE(WIFSIGNALED(end.status)) << end.status;
  EXPECT_EQ(WTERMSIG(end.status), SIGABRT);
}

TEST(ScopedStderrCapture, InterruptOrTerminateInsideTheScopeWritesTheHeldLinesAndStillEnds) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const ChildEnd end = RunChild([signal] { PrintsThenEnds([signal] { std::raise(signal); }); });
    EXPECT_EQ(end.err, kHeld) << signal;
    ASSERT_TRUE(WIFSIGNALED(end.status)) << signal << " " << end.status;
    EXPECT_EQ(WTERMSIG(end.status), signal);
  }
}

// A process that ignores Ctrl-C (started under nohup, say) goes on ignoring it
// inside the scope: no handler of the scope's takes its place (one would give
// the held lines out there and then, the noise too).
TEST(ScopedStderrCapture, AnIgnoredSignalStaysIgnored) {
  const ChildEnd end = RunChild([] {
    std::signal(SIGINT, SIG_IGN);
    {
      ScopedStderrCapture capture(IsNoise);
      std::fprintf(stderr, "noise: going again\nkept: solved\n");
      std::raise(SIGINT);
    }
    std::exit(5);
  });
  EXPECT_EQ(end.err, "kept: solved\n");
  ASSERT_TRUE(WIFEXITED(end.status)) << end.status;
  EXPECT_EQ(WEXITSTATUS(end.status), 5);
}

// Nested, the inner scope's lines go to the outer's file first, then all of
// it out, in the order written.
TEST(ScopedStderrCapture, ExitInsideNestedScopesWritesBothScopesLinesInOrder) {
  const ChildEnd end = RunChild([] {
    ScopedStderrCapture outer(IsNoise);
    std::fprintf(stderr, "kept: outer\n");
    ScopedStderrCapture inner(IsNoise);
    std::fprintf(stderr, "kept: inner\n");
    std::exit(1);
  });
  EXPECT_EQ(end.err, "kept: outer\nkept: inner\n");
  ASSERT_TRUE(WIFEXITED(end.status)) << end.status;
  EXPECT_EQ(WEXITSTATUS(end.status), 1);
}

// A handler the program had installed before the scope is its handler again
// after it (here a no-op one on SIGINT and SIGTERM, so a scope that reset
// them to SIG_DFL would fail), and inside the scope it is not (the scope's
// own handler is installed).
void DoNothingOnSignal(int) {}

TEST(ScopedStderrCapture, LeavesTheSignalDispositionsAsItFoundThem) {
  for (const int signal : {SIGINT, SIGTERM}) {
    struct sigaction original {};
    struct sigaction no_op {};
    no_op.sa_handler = DoNothingOnSignal;
    sigemptyset(&no_op.sa_mask);
    ASSERT_EQ(sigaction(signal, &no_op, &original), 0) << signal;
    {
      ScopedStderrCapture capture(IsNoise);
      struct sigaction inside {};
      sigaction(signal, nullptr, &inside);
      EXPECT_NE(inside.sa_handler, &DoNothingOnSignal) << signal;
    }
    struct sigaction after {};
    sigaction(signal, nullptr, &after);
    EXPECT_EQ(after.sa_handler, &DoNothingOnSignal) << signal;
    sigaction(signal, &original, nullptr);
  }
}

}  // namespace
}  // namespace stereorig
