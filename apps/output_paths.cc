#include "apps/output_paths.h"

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

std::filesystem::path Key(const std::string& path) {
  return std::filesystem::absolute(std::filesystem::path(path)).lexically_normal();
}

}  // namespace

void OutputPaths::Protect(const std::string& path, const std::string& what) {
  if (!path.empty()) inputs_.emplace(Key(path), what);
}

void OutputPaths::Claim(const std::string& path, const std::string& what, bool check_folder) {
  namespace fs = std::filesystem;
  const fs::path key = Key(path);
  if (const auto it = inputs_.find(key); it != inputs_.end())
    throw InputError(path, "is " + it->second + ": writing " + what + " there would overwrite an input");
  if (const auto it = claimed_.find(key); it != claimed_.end())
    throw InputError(
        path, "would be written twice (" + it->second + " and " + what + ")" + (remedy_.empty() ? "" : ": " + remedy_));
  if (check_folder && !fs::is_directory(key.parent_path())) throw InputError(path, "its folder does not exist");
  if (fs::is_directory(key)) throw InputError(path, "is a folder, not a file to write");
  claimed_.emplace(key, what);
}

}  // namespace stereorig
