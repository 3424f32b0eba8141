#include "calib/core/input_file.h"

#include <filesystem>

#include "calib/core/input_error.h"

namespace stereorig {

void RequireInputFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a folder, not a file");
  throw InputError(path, "no such file");
}

}  // namespace stereorig
