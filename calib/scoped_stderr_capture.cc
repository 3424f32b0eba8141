#include "calib/scoped_stderr_capture.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>
#include <utility>

namespace stereorig {
namespace {

std::recursive_mutex& StderrMutex() {
  static std::recursive_mutex m;
  return m;
}

// All of `text` to `fd`, through short writes and signals.
void WriteAll(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = write(fd, text.data(), text.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // stderr itself is gone: nowhere left to say it
    text.remove_prefix(static_cast<size_t>(n));
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

}  // namespace

ScopedStderrCapture::ScopedStderrCapture(std::function<bool(std::string_view line)> drop)
    : drop_(std::move(drop)), lock_(StderrMutex()) {
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
  }
}

ScopedStderrCapture::~ScopedStderrCapture() {
  if (capture_fd_ < 0) return;
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
  WriteAll(STDERR_FILENO, kept);
}

}  // namespace stereorig
