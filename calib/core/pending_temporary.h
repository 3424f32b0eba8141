// Temporary outputs that a termination signal removes. A line's process
// stopped mid-write (SIGTERM from its supervisor, Ctrl-C) would otherwise
// leave hidden .tmp-* files beside its outputs (atomic_file.h), or a
// simulated dataset's temporary folder of hundreds of images
// (datasets/simulate.cc): harmless to the outputs, but they pile up. While
// a PendingTemporary lives, SIGTERM, SIGINT, SIGHUP or SIGPIPE removes its
// file, or its folder and all in it (signal_safe_removal.h: links not
// followed, at most kMaxRemovalDepth levels), then the process dies of the
// signal as it would have.
//
// A folder the process made (kEmptyFolder: FolderToCreate's, folder_to_create.h)
// is removed only while empty (rmdir), after the files and trees, innermost
// first whatever order they were registered in.
//
// The handlers are installed on first use, for each of those signals whose
// handler is still the default (a program's own handler is left alone).
// Best effort: at most kMaxPending at once, paths under PATH_MAX.
#pragma once

#include <string>

namespace stereorig {

enum class TemporaryKind {
  kFile,         // unlinked
  kFolder,       // removed with all in it
  kEmptyFolder,  // removed only if empty (once the others are gone)
};

class PendingTemporary {
 public:
  // score --diagnose holds four images per scene and module until its
  // report is written, all or none, and on a re-run over an earlier folder
  // a kept link per replaced file as well (AtomicOutputSet): ~2 x 4 x
  // scenes x modules, 264 on the ring of three modules with 11 scenes.
  // 1024 slots of PATH_MAX are 4 MB of address space, touched only as far
  // as they are used (the constructor takes the first free slot).
  static constexpr int kMaxPending = 1024;

  explicit PendingTemporary(const std::string& path, TemporaryKind kind = TemporaryKind::kFile);
  ~PendingTemporary() { Release(); }
  PendingTemporary(const PendingTemporary&) = delete;
  PendingTemporary& operator=(const PendingTemporary&) = delete;

  // The file or folder is gone (renamed into place or removed): a signal
  // no longer touches it.
  void Release();

 private:
  int slot_ = -1;  // -1: not registered
};

}  // namespace stereorig
