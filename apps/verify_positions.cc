#include "apps/verify_positions.h"

#include <algorithm>
#include <cmath>
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

void MarkSameFits(const std::vector<std::vector<double>>& fitted_mm, std::vector<RepeatedPosition>* repeated) {
  auto same_fit = [&](size_t i, size_t j) {
    if (fitted_mm[i].empty() || fitted_mm[i].size() != fitted_mm[j].size()) return false;
    for (size_t k = 0; k < fitted_mm[i].size(); ++k)
      if (!(std::abs(fitted_mm[i][k] - fitted_mm[j][k]) <= kSameFitMm)) return false;
    return true;
  };
  for (size_t i = 1; i < fitted_mm.size() && i < repeated->size(); ++i) {
    if ((*repeated)[i].earlier >= 0) continue;
    for (size_t j = 0; j < i; ++j) {
      if ((*repeated)[j].earlier >= 0 || !same_fit(i, j)) continue;
      (*repeated)[i].earlier = static_cast<int>(j);
      (*repeated)[i].same_fit = true;
      break;
    }
  }
}

}  // namespace stereorig
