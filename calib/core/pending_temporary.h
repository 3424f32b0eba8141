// Temporary output files that a termination signal removes. A line's
// process stopped mid-write (SIGTERM from its supervisor, Ctrl-C) would
// otherwise leave hidden .tmp-* files beside its outputs (atomic_file.h):
// harmless to the outputs, but they pile up. While a PendingTemporary
// lives, SIGTERM, SIGINT or SIGHUP unlinks its file, then the process dies
// of the signal as it would have.
//
// The handlers are installed on first use, for each of those signals whose
// handler is still the default (a program's own handler is left alone).
// Best effort: at most kMaxPending files at once, paths under PATH_MAX.
#pragma once

#include <string>

namespace stereorig {

class PendingTemporary {
 public:
  static constexpr int kMaxPending = 128;

  explicit PendingTemporary(const std::string& path);
  ~PendingTemporary() { Release(); }
  PendingTemporary(const PendingTemporary&) = delete;
  PendingTemporary& operator=(const PendingTemporary&) = delete;

  // The file is gone (renamed into place or removed): a signal no longer
  // touches it.
  void Release();

 private:
  int slot_ = -1;  // -1: not registered
};

}  // namespace stereorig
