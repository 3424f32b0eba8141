#include "calib/scoped_stderr_capture.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
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

}  // namespace
}  // namespace stereorig
