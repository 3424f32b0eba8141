#include "calib/core/folder_to_create.h"

#include <algorithm>
#include <utility>

#include "calib/core/input_error.h"

namespace stereorig {

namespace fs = std::filesystem;

namespace {

// Symbolic links followed as far as the path exists, the rest normalised
// (as apps/output_paths.cc compares paths).
fs::path Normal(const fs::path& path) { return fs::weakly_canonical(fs::absolute(path)); }

}  // namespace

FolderToCreate::FolderToCreate(const std::string& path, const std::string& what) : path_(path), what_(what) {
  for (fs::path p = Normal(path); !p.empty() && !fs::exists(p); p = p.parent_path()) {
    missing_.insert(missing_.begin(), p);  // outermost first
    if (p == p.root_path()) break;
  }
}

FolderToCreate::FolderToCreate(FolderToCreate&& other) noexcept
    : path_(std::move(other.path_)),
      what_(std::move(other.what_)),
      missing_(std::move(other.missing_)),
      created_(std::exchange(other.created_, false)),
      exceptions_(other.exceptions_) {}

FolderToCreate& FolderToCreate::operator=(FolderToCreate&& other) noexcept {
  if (this != &other) {
    path_ = std::move(other.path_);
    what_ = std::move(other.what_);
    missing_ = std::move(other.missing_);
    created_ = std::exchange(other.created_, false);
    exceptions_ = other.exceptions_;
  }
  return *this;
}

FolderToCreate::~FolderToCreate() {
  if (std::uncaught_exceptions() > exceptions_) RemoveIfEmpty();  // failing
}

bool FolderToCreate::WillCreate(const fs::path& folder) const {
  return std::find(missing_.begin(), missing_.end(), Normal(folder)) != missing_.end();
}

void FolderToCreate::Create() {
  if (path_.empty()) return;
  created_ = true;  // before: a failure part way leaves folders to remove
  std::error_code ec;
  fs::create_directories(path_, ec);
  if (ec || !fs::is_directory(path_))
    throw InputError(path_, "cannot create this folder for " + what_ + (ec ? ": " + ec.message() : ""));
}

void FolderToCreate::RemoveIfEmpty() {
  if (!created_) return;
  created_ = false;
  std::error_code ec;
  for (auto p = missing_.rbegin(); p != missing_.rend(); ++p) {  // innermost first
    if (!fs::exists(*p, ec)) continue;                           // not made (Create failed part way)
    if (!fs::remove(*p, ec)) break;                              // not empty: it and the folders above it stay
  }
}

}  // namespace stereorig
