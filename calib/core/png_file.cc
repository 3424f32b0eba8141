#include "calib/core/png_file.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>

#include "calib/core/input_error.h"

namespace stereorig {

bool CheckPngIsWhole(const std::string& path) {
  // The 8-byte signature, and the last chunk: length 0, type "IEND", its CRC.
  static constexpr std::array<uint8_t, 8> kSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  static constexpr std::array<uint8_t, 12> kEnd = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path, "cannot be opened");
  std::array<uint8_t, 8> head{};
  if (!f.read(reinterpret_cast<char*>(head.data()), head.size()) || head != kSignature) return false;
  // IEND closes the image; libpng ignores bytes after it, so it is looked
  // for in the file's last 4 KiB rather than only at its very end.
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  const std::streamoff span = std::min<std::streamoff>(size - std::streamoff(head.size()), 4096);
  std::string tail(size_t(std::max<std::streamoff>(span, 0)), '\0');
  f.seekg(size - span);
  f.read(tail.data(), std::streamsize(tail.size()));
  const std::string end(reinterpret_cast<const char*>(kEnd.data()), kEnd.size());
  if (!f || tail.find(end) == std::string::npos)
    throw InputError(path, "a PNG cut short (no IEND chunk at its end: still being written?)");
  return true;
}

}  // namespace stereorig
