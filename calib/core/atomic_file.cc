#include "atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "input_error.h"

namespace stereorig {

namespace {

std::string MakeTempPath(const std::string& path) {
  static std::atomic<int> counter{0};
  const std::filesystem::path p(path);
  const std::string stem = ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-";
  return (p.parent_path() / (stem + p.filename().string())).string();
}

}  // namespace

AtomicOutput::AtomicOutput(const std::string& path)
    : path_(path), temp_path_(MakeTempPath(path)), pending_(temp_path_) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw InputError(path, "output folder '" + parent.string() + "' does not exist");
  }
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_path_.c_str());
  pending_.Release();
}

void AtomicOutput::Commit() {
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const std::string err = std::strerror(errno);
    std::remove(temp_path_.c_str());
    throw InputError(path_, "cannot write: " + err);
  }
  pending_.Release();
  committed_ = true;
}

namespace {

// `bytes` into out's temporary file, synced; InputError naming `path`.
void WriteTemporary(const AtomicOutput& out, const std::string& path, const std::string& bytes) {
  FILE* f = std::fopen(out.temp_path().c_str(), "wb");
  if (!f) throw InputError(path, std::string("cannot write: ") + std::strerror(errno));
  const bool ok =
      std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0 && fsync(fileno(f)) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) throw InputError(path, "write failed (disk full?)");
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  AtomicOutput out(path);
  WriteTemporary(out, path, bytes);
  out.Commit();
}

void AtomicOutputSet::Add(const std::string& path, const std::string& bytes) {
  auto out = std::make_unique<AtomicOutput>(path);
  WriteTemporary(*out, path, bytes);  // on failure `out` removes its temporary file
  staged_.push_back(std::move(out));
}

void AtomicOutputSet::Commit() {
  for (const std::unique_ptr<AtomicOutput>& out : staged_) out->Commit();
  staged_.clear();
}

}  // namespace stereorig
