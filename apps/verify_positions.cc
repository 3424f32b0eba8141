#include "apps/verify_positions.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

namespace stereorig {

namespace {

// Whether two files of the same size hold the same bytes; false if either
// cannot be read (the reader then names it).
bool SameBytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  if (!fa || !fb) return false;
  constexpr size_t kChunk = 1 << 16;
  std::vector<char> ba(kChunk), bb(kChunk);
  while (fa && fb) {
    fa.read(ba.data(), kChunk);
    fb.read(bb.data(), kChunk);
    if (fa.gcount() != fb.gcount() || !std::equal(ba.begin(), ba.begin() + fa.gcount(), bb.begin())) return false;
  }
  return fa.eof() && fb.eof();
}

}  // namespace

std::vector<RepeatedPosition> RepeatedPositions(const std::vector<std::string>& clouds) {
  namespace fs = std::filesystem;
  std::vector<RepeatedPosition> repeated(clouds.size());
  std::vector<std::uintmax_t> sizes;
  for (const std::string& cloud : clouds) {
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(cloud, ec);
    sizes.push_back(ec ? static_cast<std::uintmax_t>(-1) : size);
  }
  for (size_t i = 1; i < clouds.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      std::error_code ec;
      if (fs::equivalent(clouds[i], clouds[j], ec)) {
        repeated[i] = {static_cast<int>(j), true};
        break;
      }
      if (sizes[i] != static_cast<std::uintmax_t>(-1) && sizes[i] == sizes[j] && SameBytes(clouds[i], clouds[j])) {
        repeated[i] = {static_cast<int>(j), false};
        break;
      }
    }
  }
  return repeated;
}

}  // namespace stereorig
