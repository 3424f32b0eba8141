#include "reconstruct/window_sums.h"

namespace stereorig {

void AddRow(const float* __restrict in, int width, float* __restrict acc) {
  for (int x = 0; x < width; ++x) acc[x] += in[x];
}

void SumAlongRow(const float* __restrict in, int width, int half_width, float* __restrict out) {
  const int n = 2 * half_width + 1;
  for (int x = half_width; x < width - half_width; ++x) {
    const float* p = in + x - half_width;
    float s = 0;
    for (int k = 0; k < n; ++k) s += p[k];
    out[x] = s;
  }
}

}  // namespace stereorig
