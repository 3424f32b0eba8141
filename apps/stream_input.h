// The lines of a stream's input (apps/reconstruct_stream.h), read so that a
// stop signal ends the stream cleanly. A line process is stopped by its
// supervisor: systemd's `stop` sends SIGTERM (and SIGHUP right after it with
// SendSIGHUP=yes), a terminal's Ctrl-C SIGINT, its hang-up SIGHUP.
// Killed by the signal's default action, the stream would write no summary
// (its totals and failed captures); with a StreamInput it finishes the
// capture it is on, reads no further line and ends as at the end of its
// input, summary written.
//
// How no signal is lost: while a StreamInput exists, SIGTERM, SIGINT and
// SIGHUP are blocked in the thread that made it and in every thread started after it
// (threads inherit the mask: the runtime's pool, built afterwards), and they
// are let in only inside Next()'s wait for input (ppoll, which unblocks them
// and waits in one step). A signal sent while a capture is reconstructed or
// written stays pending until that capture is done; Next() then takes it
// (sigtimedwait) before it begins another line, whether or not input is
// waiting (lines queued in a pipe, a file given as the input). One sent
// during the wait ends it at once. Should a thread started before the
// StreamInput take one (none does in stereorig), its handler wakes the wait
// through a pipe. A process started with one of them ignored (`nohup`'s
// SIGHUP, a shell's background job's SIGINT) keeps it ignored. A stop signal
// that comes after the input has ended changes nothing: the stream is
// ending. SIGPIPE is ignored from the StreamInput on: a stdout whose reader
// went away fails the write (EPIPE), which the stream takes as its end.
#pragma once

#include <csignal>
#include <string>

namespace stereorig {

class StreamInput {
 public:
  // Reads `fd` (a pipe, a FIFO, a file); does not own it. One at a time.
  explicit StreamInput(int fd);
  // The thread's signal mask as it was; the handlers stay (a signal after
  // the stream, as the process returns its exit code, changes nothing).
  ~StreamInput();
  StreamInput(const StreamInput&) = delete;
  StreamInput& operator=(const StreamInput&) = delete;

  // The next line, without its '\n' (the input's last line may lack one).
  // False at the end of the input, when a stop signal came (stop_signal()),
  // or when the input cannot be read (error()); a line that was only partly
  // read when the signal came is dropped, as it may be incomplete.
  bool Next(std::string* line);

  int stop_signal() const;                             // SIGTERM, SIGINT, SIGHUP, or 0
  const std::string& error() const { return error_; }  // "" or why the input could not be read

 private:
  void TakePendingStop();  // a handled signal pending (blocked) becomes the stop

  int fd_;
  std::string buffer_;  // read but not yet returned
  size_t begin_ = 0;    // where buffer_'s next line starts
  bool at_end_ = false;
  std::string error_;
  int wake_[2] = {-1, -1};  // the handler's self-pipe: read end, write end
  sigset_t handled_;        // the stop signals handled (not ignored at the start)
  sigset_t old_mask_;       // the thread's mask before
};

// "SIGTERM", "SIGINT", "SIGHUP", or "signal N".
std::string SignalName(int signal);

}  // namespace stereorig
