// Holds what the process writes to stderr while a scope runs, and writes it
// back when the scope ends, but for the lines the caller drops. For a C
// library that prints on fd 2 on its own, whatever its flags: libmrcal's
// mrcal_optimize prints its outlier loop ("mrcal.c(5351): Threw out some
// outliers (have a total of 1737 now); going again") with a total that is not
// the outlier count a user reads in our report (calib/mrcal_problem.cc).
#pragma once

#include <functional>
#include <mutex>
#include <string_view>

namespace stereorig {

// fd 2 itself is redirected (to an unlinked temporary file), so it catches
// fprintf(stderr), std::cerr, glog and write(2) alike, from any thread.
// Another thread's lines in the meantime are held too, and come out
// unchanged, only later (at the scope's end), unless `drop` picks them.
// If the process ends inside the scope (a library's exit(): libdogleg's on a
// failed assertion; abort(); SIGSEGV, SIGBUS, SIGFPE; Ctrl-C or SIGTERM),
// all that was held comes out first, unfiltered, since it is what says why,
// and the process ends as it would have, with the same exit code or signal.
// Those signal handlers are there only while a scope is open; a signal the
// process ignores stays ignored. _exit() and SIGKILL lose the held lines.
// Scopes in two threads run one after the other (a process has one fd 2: the
// second would otherwise restore the first's file as stderr): a second
// thread's scope waits for the first's to end, so two threads' mrcal solves
// take turns (target_study --threads 2 times the wait into its
// s/calibration). Nested in one thread, each ends where it began (up to 8
// deep; deeper ones pass stderr through). If the temporary file cannot be
// made, nothing is captured and stderr passes through as it is.
class ScopedStderrCapture {
 public:
  // `drop(line)` (the line without its '\n'): true leaves the line out.
  explicit ScopedStderrCapture(std::function<bool(std::string_view line)> drop);
  ~ScopedStderrCapture();
  ScopedStderrCapture(const ScopedStderrCapture&) = delete;
  ScopedStderrCapture& operator=(const ScopedStderrCapture&) = delete;

 private:
  std::function<bool(std::string_view)> drop_;
  std::unique_lock<std::recursive_mutex> lock_;
  int stderr_fd_ = -1;   // a copy of the real fd 2, while captured
  int capture_fd_ = -1;  // the temporary file fd 2 points at meanwhile
  int depth_ = 0;        // the scopes open around this one
};

}  // namespace stereorig
