#include "apps/stream_input.h"

#include <poll.h>
#include <pthread.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace stereorig {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
bool g_active = false;  // a StreamInput exists (the handlers and the flag are the process's)

extern "C" void OnStopSignal(int signal) { g_stop_signal = signal; }

sigset_t StopSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  return set;
}

// Installs the handler for `signal` unless the process was started with it
// ignored (`nohup`, a shell's background job's SIGINT): then it stays
// ignored, as the one who started the process asked.
void Install(int signal, struct sigaction* old) {
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: ppoll returns EINTR
  sigaction(signal, nullptr, old);
  if (old->sa_handler != SIG_IGN) sigaction(signal, &action, nullptr);
}

}  // namespace

StreamInput::StreamInput(int fd) : fd_(fd) {
  if (g_active) throw std::logic_error("StreamInput: one at a time");
  g_active = true;
  g_stop_signal = 0;
  const sigset_t stop = StopSignals();
  pthread_sigmask(SIG_BLOCK, &stop, &old_mask_);
  Install(SIGTERM, &old_term_);
  Install(SIGINT, &old_int_);
}

StreamInput::~StreamInput() {
  // A stop signal still pending (it came while the last capture was done,
  // after the input had ended) is taken here: restored to its default
  // action, it would kill the process before it returns its exit code.
  const sigset_t stop = StopSignals();
  const timespec now{0, 0};
  while (sigtimedwait(&stop, nullptr, &now) > 0) {
  }
  sigaction(SIGTERM, &old_term_, nullptr);
  sigaction(SIGINT, &old_int_, nullptr);
  pthread_sigmask(SIG_SETMASK, &old_mask_, nullptr);
  g_active = false;
}

int StreamInput::stop_signal() const { return g_stop_signal; }

bool StreamInput::Next(std::string* line) {
  // The stop signals are let in only while waiting, as the mask the process
  // had before (one that blocked them blocks them no longer: a stream must
  // be stoppable).
  sigset_t wait_mask = old_mask_;
  sigdelset(&wait_mask, SIGTERM);
  sigdelset(&wait_mask, SIGINT);
  for (;;) {
    if (g_stop_signal != 0) return false;  // lines read already are not begun either
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
    pollfd ready{fd_, POLLIN, 0};
    if (ppoll(&ready, 1, nullptr, &wait_mask) < 0) {
      if (errno == EINTR) continue;  // a stop signal (checked above) or another handled one
      error_ = std::strerror(errno);
      return false;
    }
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
  return "signal " + std::to_string(signal);
}

}  // namespace stereorig
