#include "calib/core/png_file.h"

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
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  std::array<uint8_t, 12> tail{};
  if (size >= std::streamoff(head.size() + tail.size())) {
    f.seekg(size - std::streamoff(tail.size()));
    f.read(reinterpret_cast<char*>(tail.data()), tail.size());
  }
  if (!f || tail != kEnd)
    throw InputError(path, "a PNG cut short (it does not end with its IEND chunk: still being written?)");
  return true;
}

}  // namespace stereorig
