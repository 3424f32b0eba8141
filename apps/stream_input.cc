#include "apps/stream_input.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace stereorig {

namespace {

// SIGHUP too: a terminal that hangs up, and systemd's SendSIGHUP=yes right
// after its SIGTERM, would otherwise kill the stream mid-capture (its
// temporary files removed, no summary) where SIGTERM lets it finish.
constexpr int kStopSignals[] = {SIGTERM, SIGINT, SIGHUP};

volatile std::sig_atomic_t g_stop_signal = 0;
int g_wake_fd = -1;     // the self-pipe's write end: the handler wakes Next()'s wait from any thread
bool g_active = false;  // a StreamInput exists (the handlers, the flag and the pipe are the process's)

extern "C" void OnStopSignal(int signal) {
  g_stop_signal = signal;
  const int saved_errno = errno;
  const char byte = 1;
  [[maybe_unused]] const ssize_t ignored = write(g_wake_fd, &byte, 1);  // full pipe: a byte is there already
  errno = saved_errno;
}

// Installs the handler for `signal` and adds it to `handled`, unless the
// process was started with it ignored (`nohup`, a shell's background job's
// SIGINT): then it stays ignored, as the one who started the process asked
// (and is not blocked: a blocked signal is kept pending even when ignored).
void Install(int signal, sigset_t* handled) {
  struct sigaction old {};
  sigaction(signal, nullptr, &old);
  if (old.sa_handler == SIG_IGN) return;
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: ppoll returns EINTR
  sigaction(signal, &action, nullptr);
  sigaddset(handled, signal);
}

}  // namespace

StreamInput::StreamInput(int fd) : fd_(fd) {
  if (g_active) throw std::logic_error("StreamInput: one at a time");
  if (pipe2(wake_, O_NONBLOCK | O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  g_active = true;
  g_stop_signal = 0;
  g_wake_fd = wake_[1];
  sigemptyset(&handled_);
  for (int s : kStopSignals) Install(s, &handled_);
  // A reader of stdout that went away (the supervisor died) makes the
  // capture's line fail with EPIPE, which ends the stream with its summary
  // (reconstruct_stream.cc), instead of SIGPIPE killing it.
  std::signal(SIGPIPE, SIG_IGN);
  // One that comes between its handler and its mask sets the flag and
  // wakes the first wait: it stops the stream all the same.
  pthread_sigmask(SIG_BLOCK, &handled_, &old_mask_);
}

StreamInput::~StreamInput() {
  // A stop signal still pending (it came while the last capture was done,
  // after the input had ended) is taken here; the handlers stay installed:
  // the stream has ended and the process is returning its exit code, which
  // a signal restored to its default action could still turn into a death
  // by that signal in the instant before the mask is put back.
  TakePendingStop();
  pthread_sigmask(SIG_SETMASK, &old_mask_, nullptr);
  g_wake_fd = -1;
  close(wake_[0]);
  close(wake_[1]);
  g_active = false;
}

int StreamInput::stop_signal() const { return g_stop_signal; }

void StreamInput::TakePendingStop() {
  const timespec now{0, 0};
  for (int s; (s = sigtimedwait(&handled_, nullptr, &now)) > 0;) g_stop_signal = s;
}

bool StreamInput::Next(std::string* line) {
  // The stop signals are let in only while waiting, as the mask the process
  // had before (one that blocked them blocks them no longer: a stream must
  // be stoppable).
  sigset_t wait_mask = old_mask_;
  for (int s : kStopSignals)
    if (sigismember(&handled_, s)) sigdelset(&wait_mask, s);
  for (;;) {
    // One sent while a capture was done is pending (blocked): it is taken
    // here, before any line, read or buffered, is begun. Waiting for input
    // would not take it when input is ready (ppoll then returns at once
    // without letting it in).
    TakePendingStop();
    if (g_stop_signal != 0) return false;
    const size_t newline = buffer_.find('\n', begin_);
    if (newline != std::string::npos) {
      line->assign(buffer_, begin_, newline - begin_);
      begin_ = newline + 1;
      return true;
    }
    if (at_end_) {
      if (begin_ == buffer_.size()) return false;
      line->assign(buffer_, begin_, std::string::npos);  // the last line, without a newline
      begin_ = buffer_.size();
      return true;
    }
    buffer_.erase(0, begin_);
    begin_ = 0;
    pollfd ready[2] = {{fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    if (ppoll(ready, 2, nullptr, &wait_mask) < 0) {
      if (errno == EINTR) continue;  // a stop signal (checked above) or another handled one
      error_ = std::strerror(errno);
      return false;
    }
    if (ready[1].revents != 0) continue;  // the handler ran on another thread: the flag is set
    char chunk[4096];
    const ssize_t got = read(fd_, chunk, sizeof chunk);
    if (got < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      error_ = std::strerror(errno);
      return false;
    }
    if (got == 0) {
      at_end_ = true;
      continue;
    }
    buffer_.append(chunk, size_t(got));
  }
}

std::string SignalName(int signal) {
  if (signal == SIGTERM) return "SIGTERM";
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGHUP) return "SIGHUP";
  return "signal " + std::to_string(signal);
}

}  // namespace stereorig
