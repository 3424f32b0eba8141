// Outputs are written atomically: to a temporary file beside the target, then
// renamed over it. A failure at any point leaves either the old file or no
// file, never a half-written one.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "calib/core/pending_temporary.h"

namespace stereorig {

// Throws InputError naming `path` if an output there cannot be written by
// a rename over it: "-" (a file of that name, where a user means standard
// output) and an existing device, pipe or socket (/dev/null, a FIFO: the
// rename would replace the node itself, as root a system device, with a
// regular file), or a symbolic link to one (/dev/stdout); and a path in
// /dev or /proc (but /dev/shm, a folder for files), or one whose links lead
// through one, whatever the last link points to: /dev/stdout,
// /proc/self/fd/1 are links to a stream's file too when it is redirected,
// and the rename replaced /dev/stdout itself. Any other link to a file or
// to nothing is no problem: the rename replaces the link, its target is
// left as it was. AtomicOutput checks this; commands
// check it up front too (apps/output_paths.h), before their work.
void RequireReplaceableOutput(const std::string& path);

// "" if a file can be created beside `path` (the temporary file an output
// is written to, created and removed at once), else why not (strerror).
// access(W_OK) alone says yes to root in folders no file can be made in
// (/sys, /proc): only trying tells, before a command's minutes of work.
std::string CannotCreateBeside(const std::string& path);

// Writes `bytes` to `path` atomically. Throws InputError naming `path` if the
// folder is missing or not writable, or as RequireReplaceableOutput.
void WriteFileAtomically(const std::string& path, const std::string& bytes);

// What a commit does with a file that is at an output's path by then.
enum class AtExisting {
  kReplace,  // the rename's way: the output replaces it
  // Left as it is, the output refused (InputError "exists already"): for
  // outputs never to replace, where another process may create the same
  // name between a check that it is free and the commit (two reconstruct
  // streams sharing an --out-dir). Committed by RenameWithoutReplacing.
  kRefuse,
};

// A call taking two paths, as rename(2): 0, or -1 with errno set.
using PathCall = int (*)(const char* from, const char* to);

// Renames `from` to `to` unless a file is at `to` (a dangling link too):
// returns 0, or the errno (EEXIST: one is there; `from` is then left).
// By renameat2(RENAME_NOREPLACE), or where the file system has no such
// rename, a hard link and `from`'s removal: either fails if the name
// exists, atomically. Where it makes no hard links either (some FUSE
// mounts: sshfs, SMB, WSL's drvfs), the name is checked free, then renamed:
// a file made in the moment between is replaced, but the output is
// written. `rename_noreplace` and `hard_link`, null for the system's, are
// for tests standing in such a file system.
int RenameWithoutReplacing(const char* from, const char* to, PathCall rename_noreplace = nullptr,
                           PathCall hard_link = nullptr);

// For writers that need a path of their own (cv::imwrite, sqlite, ...):
// write to temp_path(), then Commit(). If Commit() is never called the
// temporary file is removed.
class AtomicOutput {
 public:
  explicit AtomicOutput(const std::string& path);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  // Same folder and extension as the final path, so format-by-extension
  // writers still work.
  const std::string& temp_path() const { return temp_path_; }
  const std::string& path() const { return path_; }  // the final path
  // Renames; throws InputError on failure, the temporary file removed.
  void Commit(AtExisting existing = AtExisting::kReplace);

 private:
  std::string path_;
  std::string temp_path_;
  PendingTemporary pending_;  // removed by a termination signal while it exists
  bool committed_ = false;
};

// The outputs of one run, all or none: Add writes each to its temporary
// file (failing as WriteFileAtomically does); Commit renames them all, once
// every one is written. Destroyed before Commit (a later output failed), it
// removes the temporary files: a run that fails while writing its second or
// third output (a full disk) leaves every file at its output paths as it
// was, not the first output new and the rest old. A rename that fails
// within Commit (an immutable or busy file) puts back what the renames
// before it replaced (kept under a second name, a hard link, until all are
// done) and removes what they added; where the file system makes no hard
// link, that one earlier file cannot be put back.
class AtomicOutputSet {
 public:
  void Add(const std::string& path, const std::string& bytes);
  // In the order added. kReplace: throws InputError on a failed rename, the
  // earlier files put back. kRefuse: none replaces a file; one that exists
  // by then refuses the set ("exists already"), and what the commits before
  // it added is removed (nothing was there before them), so the set leaves
  // every output path as it was. The first output then decides a race
  // between two sets of the same names in the same order: the set that
  // commits it first writes all, the other none; and once the last (a
  // report) is there, so are the others.
  void Commit(AtExisting existing = AtExisting::kReplace);

 private:
  void CommitReplacing();
  void CommitNew();

  std::vector<std::unique_ptr<AtomicOutput>> staged_;
};

}  // namespace stereorig
