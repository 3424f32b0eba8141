#include "calib/scoped_stderr_capture.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

namespace stereorig {
namespace {

std::recursive_mutex& StderrMutex() {
  static std::recursive_mutex m;
  return m;
}

// All of `text` to `fd`, through short writes and signals. write(2) only:
// safe in a signal handler.
void WriteAll(int fd, const char* text, size_t size) {
  while (size > 0) {
    const ssize_t n = write(fd, text, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // stderr itself is gone: nowhere left to say it
    text += n;
    size -= static_cast<size_t>(n);
  }
}

std::string ReadAll(int fd) {
  std::string text;
  if (lseek(fd, 0, SEEK_SET) != 0) return text;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return text;
    text.append(buf, static_cast<size_t>(n));
  }
}

// What the process-ending paths (exit() from a library, abort(), a fatal or
// stop signal) need to give the held lines out: the open scopes' fds, outermost
// first. Plain lock-free atomics, read by a signal handler; written under
// StderrMutex(), each entry before `g_depth` counts it.
static_assert(std::atomic<int>::is_always_lock_free);
constexpr int kMaxDepth = 8;
struct HeldFds {
  std::atomic<int> stderr_fd{-1};
  std::atomic<int> capture_fd{-1};
};
HeldFds g_held[kMaxDepth];
std::atomic<int> g_depth{0};

constexpr int kEndingSignals[] = {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGINT, SIGTERM};
constexpr int kNumEndingSignals = sizeof kEndingSignals / sizeof kEndingSignals[0];
struct sigaction g_previous[kNumEndingSignals];
std::atomic<bool> g_handlers_installed{false};

// Gives fd 2 back and copies each open scope's file to where its scope found
// fd 2, innermost first (an inner scope found the outer one's file), so the
// outermost copy writes everything, in the order it was written. Unfiltered:
// when the process ends there, a line too many beats a line lost. Only
// dup2, lseek, read and write: async-signal-safe.
void DrainHeld() {
  for (int i = g_depth.exchange(0) - 1; i >= 0; --i) {
    const int stderr_fd = g_held[i].stderr_fd.load();
    const int capture_fd = g_held[i].capture_fd.load();
    dup2(stderr_fd, STDERR_FILENO);
    if (lseek(capture_fd, 0, SEEK_SET) != 0) continue;
    char buf[4096];
    for (;;) {
      const ssize_t n = read(capture_fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      WriteAll(STDERR_FILENO, buf, static_cast<size_t>(n));
    }
  }
}

void RestoreHandlers() {
  if (!g_handlers_installed.exchange(false)) return;
  for (int i = 0; i < kNumEndingSignals; ++i) sigaction(kEndingSignals[i], &g_previous[i], nullptr);
}

// The held lines out, then the signal as if no scope had been open: the
// previous disposition, raised again (delivered when this returns), so the
// process ends with the status it would have had.
void OnEndingSignal(int signal) {
  const int saved_errno = errno;
  DrainHeld();
  RestoreHandlers();
  raise(signal);
  errno = saved_errno;
}

// A library's exit() (libdogleg's on a failed assertion) runs this: the lines
// that say why reach the terminal.
void DrainAtExit() {
  std::fflush(stderr);
  DrainHeld();
  RestoreHandlers();
}

// Only while a scope is open: outside, the process's signals are its own. A
// signal the process ignores stays ignored.
void InstallHandlers() {
  static const bool at_exit_registered = std::atexit(DrainAtExit) == 0;
  (void)at_exit_registered;
  struct sigaction action {};
  action.sa_handler = OnEndingSignal;
  sigfillset(&action.sa_mask);  // one drain at a time
  for (int i = 0; i < kNumEndingSignals; ++i) {
    sigaction(kEndingSignals[i], nullptr, &g_previous[i]);
    if (g_previous[i].sa_handler != SIG_IGN) sigaction(kEndingSignals[i], &action, nullptr);
  }
  g_handlers_installed = true;
}

}  // namespace

ScopedStderrCapture::ScopedStderrCapture(std::function<bool(std::string_view line)> drop)
    : drop_(std::move(drop)), lock_(StderrMutex()) {
  depth_ = g_depth.load();
  if (depth_ >= kMaxDepth) return;
  // tmpfile's file is unlinked already: nothing is left behind on a crash.
  std::FILE* file = std::tmpfile();
  if (file == nullptr) return;
  capture_fd_ = dup(fileno(file));
  std::fclose(file);
  if (capture_fd_ < 0) return;
  // What stdio holds for stderr was written before the scope: out it goes.
  std::fflush(stderr);
  stderr_fd_ = dup(STDERR_FILENO);
  if (stderr_fd_ < 0 || dup2(capture_fd_, STDERR_FILENO) < 0) {
    if (stderr_fd_ >= 0) close(stderr_fd_);
    close(capture_fd_);
    stderr_fd_ = capture_fd_ = -1;
    return;
  }
  if (depth_ == 0) InstallHandlers();
  g_held[depth_].stderr_fd = stderr_fd_;
  g_held[depth_].capture_fd = capture_fd_;
  g_depth = depth_ + 1;
}

ScopedStderrCapture::~ScopedStderrCapture() {
  if (capture_fd_ < 0) return;
  // Off the list before fd 2 is given back. If an ending path has drained it
  // already (another thread's exit() while this one still solved), fd 2 is
  // back and the held lines are out: nothing is left to do.
  int open_depth = depth_ + 1;
  if (!g_depth.compare_exchange_strong(open_depth, depth_)) return;
  if (depth_ == 0) RestoreHandlers();
  std::fflush(stderr);
  dup2(stderr_fd_, STDERR_FILENO);
  close(stderr_fd_);
  const std::string text = ReadAll(capture_fd_);
  close(capture_fd_);
  std::string kept;
  for (size_t begin = 0; begin < text.size();) {
    const size_t newline = text.find('\n', begin);
    const size_t end = newline == std::string::npos ? text.size() : newline + 1;
    const std::string_view line(text.data() + begin, end - begin);
    if (!drop_(line.substr(0, newline == std::string::npos ? line.size() : line.size() - 1))) kept.append(line);
    begin = end;
  }
  WriteAll(STDERR_FILENO, kept.data(), kept.size());
}

}  // namespace stereorig
