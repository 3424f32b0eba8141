// Outputs are written atomically: to a temporary file beside the target, then
// renamed over it. A failure at any point leaves either the old file or no
// file, never a half-written one.
#pragma once

#include <string>

namespace stereorig {

// Writes `bytes` to `path` atomically. Throws InputError naming `path` if the
// folder is missing or not writable.
void WriteFileAtomically(const std::string& path, const std::string& bytes);

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
  void Commit();  // renames; throws InputError on failure

 private:
  std::string path_;
  std::string temp_path_;
  bool committed_ = false;
};

}  // namespace stereorig
