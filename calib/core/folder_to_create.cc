#include "calib/core/folder_to_create.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "calib/core/input_error.h"

namespace stereorig {

namespace fs = std::filesystem;

fs::path NormalPath(const fs::path& path) {
  const fs::path absolute = fs::absolute(path);
  std::error_code ec;
  fs::path normal = fs::weakly_canonical(absolute, ec);
  if (!ec) return normal;
  // weakly_canonical stops at a part it cannot look up (ENAMETOOLONG):
  // resolve what is above it, and keep the rest as written.
  const fs::path parent = absolute.parent_path();
  if (parent == absolute) throw fs::filesystem_error("cannot resolve the path", absolute, ec);
  return (NormalPath(parent) / absolute.filename()).lexically_normal();
}

fs::path DeepestExistingPart(const fs::path& normal, std::vector<fs::path>* missing) {
  for (fs::path p = normal; !p.empty(); p = p.parent_path()) {
    std::error_code ec;
    if (fs::exists(p, ec)) return p;
    missing->push_back(p);
    if (p == p.root_path()) break;
  }
  return {};
}

void CheckNamesFit(const std::string& path, const std::string& doing, const fs::path& existing,
                   const std::vector<fs::path>& missing) {
  if (existing.empty()) return;
  const long name_max = pathconf(existing.c_str(), _PC_NAME_MAX);
  if (name_max <= 0) return;  // no limit, or none known
  for (const fs::path& p : missing) {
    const std::string name = p.filename().string();
    if (static_cast<long>(name.size()) <= name_max) continue;
    throw InputError(path, "cannot " + doing + ": " + std::strerror(ENAMETOOLONG) + " (" + name.substr(0, 16) +
                               "...: " + std::to_string(name.size()) + " characters, more than the " +
                               std::to_string(name_max) + " the file system allows in " + existing.string() + ")");
  }
}

FolderToCreate::FolderToCreate(const std::string& path, const std::string& what) : path_(path), what_(what) {
  DeepestExistingPart(NormalPath(path), &missing_);
  std::reverse(missing_.begin(), missing_.end());  // outermost first
}

FolderToCreate::FolderToCreate(FolderToCreate&& other) noexcept
    : path_(std::move(other.path_)),
      what_(std::move(other.what_)),
      missing_(std::move(other.missing_)),
      made_(std::move(other.made_)),
      on_signal_(std::move(other.on_signal_)),
      created_(std::exchange(other.created_, false)),
      exceptions_(other.exceptions_) {}

FolderToCreate& FolderToCreate::operator=(FolderToCreate&& other) noexcept {
  if (this != &other) {
    path_ = std::move(other.path_);
    what_ = std::move(other.what_);
    missing_ = std::move(other.missing_);
    made_ = std::move(other.made_);
    on_signal_ = std::move(other.on_signal_);
    created_ = std::exchange(other.created_, false);
    exceptions_ = other.exceptions_;
  }
  return *this;
}

FolderToCreate::~FolderToCreate() {
  if (std::uncaught_exceptions() > exceptions_) RemoveIfEmpty();  // failing
}

bool FolderToCreate::WillCreate(const fs::path& folder) const {
  return std::find(missing_.begin(), missing_.end(), NormalPath(folder)) != missing_.end();
}

void FolderToCreate::Create() {
  if (path_.empty()) return;
  created_ = true;  // before: a failure part way leaves folders to remove
  // One by one, outermost first, to know which this process made: only
  // those are removed, on failure or on a signal.
  std::error_code ec;
  for (const fs::path& p : missing_) {
    if (!fs::create_directory(p, ec)) {
      if (ec) break;
      continue;  // made meanwhile by another process: not ours to remove
    }
    made_.push_back(p);
    on_signal_.push_back(std::make_unique<PendingTemporary>(p.string(), TemporaryKind::kEmptyFolder));
  }
  // A part gone since the claim (it then existed): made again, not ours.
  if (!ec) fs::create_directories(path_, ec);
  if (ec || !fs::is_directory(path_))
    throw InputError(path_, "cannot create this folder for " + what_ + (ec ? ": " + ec.message() : ""));
}

void FolderToCreate::RemoveIfEmpty() {
  if (!created_) return;
  created_ = false;
  on_signal_.clear();
  std::error_code ec;
  for (auto p = made_.rbegin(); p != made_.rend(); ++p) {  // innermost first
    if (!fs::exists(*p, ec)) continue;                     // removed by someone else
    if (!fs::remove(*p, ec)) break;                        // not empty: it and the folders above it stay
  }
}

}  // namespace stereorig
