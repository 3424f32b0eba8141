// Test helper for what a termination signal leaves behind
// (pending_temporary.h): the signal is raised in a forked child, and the
// parent looks at the files once the child is dead.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <functional>

namespace stereorig::testing {

// Runs `body` in a forked child, which ends it by raising a signal while
// what it made lives (or _exit(3) if it could not make it, or threw). Returns the
// child's wait status: exit 4 if `body` returns.
inline int StatusOfAChild(const std::function<void()>& body) {
  const pid_t child = fork();
  if (child == 0) {
    try {  // a throw must not unwind into gtest: the child would run the rest of the suite
      body();
    } catch (...) {
      _exit(3);
    }
    _exit(4);
  }
  int status = 0;
  waitpid(child, &status, 0);
  return status;
}

// Whether wait status `status` is a death by `signal`.
inline ::testing::AssertionResult DiedOf(int status, int signal) {
  if (!WIFSIGNALED(status)) return ::testing::AssertionFailure() << "child exit status " << WEXITSTATUS(status);
  if (WTERMSIG(status) != signal)
    return ::testing::AssertionFailure() << "child died of signal " << WTERMSIG(status) << ", not " << signal;
  return ::testing::AssertionSuccess();
}

}  // namespace stereorig::testing
