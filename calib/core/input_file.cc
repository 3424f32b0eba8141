#include "calib/core/input_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "calib/core/input_error.h"

namespace stereorig {

void RequireInputFile(const std::string& path, bool pipe_too) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) throw InputError(path, "no such file");
  if (ec) throw InputError(path, "cannot read it: " + ec.message());  // e.g. a folder on the way not searchable
  if (fs::is_directory(status)) throw InputError(path, "is a folder, not a file");
  if (pipe_too && fs::is_fifo(status)) return;
  if (!fs::is_regular_file(status)) throw InputError(path, "is not a regular file");
}

std::string ReadInputText(const std::string& path) {
  RequireInputFile(path, /*pipe_too=*/true);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || in.bad()) throw InputError(path, "cannot be read");
  return text.str();
}

}  // namespace stereorig
