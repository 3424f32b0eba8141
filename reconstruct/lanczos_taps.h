// The interpolation kernel of the sub-pixel fit (subpixel_refine.h,
// dense_refine.h): a tabulated Lanczos-3 kernel along the row, with its
// derivative. Both fits use this one table so the dense fit reproduces the
// per-pixel one (a cubic leaves a +-0.02 px sawtooth on ~1 px wide laser
// lines).
#pragma once

#include <array>
#include <cstdint>

namespace stereorig {

// Weights of the taps i0-2 .. i0+3 for a sample at i0 + t, t in [0,1), and of
// its derivative along x, normalised to sum to 1 (a constant is exact),
// tabulated at 1/kLanczosSteps px. The nearest entry is used: the position
// error is at most 1/(2 kLanczosSteps) = 0.002 px, uniformly spread, far
// below the noise.
//
// Each entry holds the 6 weights in lanes 2..7 of 8 (lanes 0, 1 are 0), so
// that 8 bytes loaded from column i0-4 line up with them: one 8-wide
// multiply per sample in the AVX2 fit (subpixel_window.h).
constexpr int kLanczosSteps = 256;
constexpr int kLanczosLane0 = 2;  // the lane of tap i0-2
struct alignas(32) LanczosTaps {
  float w[8], g[8];
};
using LanczosTable = std::array<LanczosTaps, kLanczosSteps + 1>;
const LanczosTable& LanczosTapTable();

namespace {  // internal linkage: each file inlines its own copy with its own compile flags

// Samples a row at the continuous column xr (row pointer `row`): value and
// slope along x. xr >= 2 and xr < width - 3 (the caller checks the reach),
// so truncation is floor.
inline void SampleLanczos(const uint8_t* row, float xr, const LanczosTable& table, float* value, float* slope) {
  const int i0 = int(xr);
  const LanczosTaps& t = table[int((xr - float(i0)) * kLanczosSteps + 0.5f)];
  const uint8_t* p = row + i0 - 2;
  float v = 0, s = 0;
  for (int k = 0; k < 6; ++k) {
    v += t.w[kLanczosLane0 + k] * p[k];
    s += t.g[kLanczosLane0 + k] * p[k];
  }
  *value = v;
  *slope = s;
}

}  // namespace
}  // namespace stereorig
