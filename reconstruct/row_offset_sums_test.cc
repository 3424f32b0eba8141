// The line index's pass sums (row_offset_sums.h) against the plain loop
// that row_offset_refine.cc ran before session 8, bit for bit: the kernel
// must do each sample's arithmetic in the same order, and this file is not
// built with FMA, so the reference rounds as the old build did.
#include "reconstruct/row_offset_sums.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace stereorig {
namespace {

RowOffsetSums PlainSums(const float* l, const float* const rk[4], const float* const gk[4], const double w[4],
                        const double dw[4], double gain, double offset, int n) {
  RowOffsetSums t;
  for (int s = 0; s < n; ++s) {
    double r = 0, rx = 0, ry = 0;
    for (int k = 0; k < 4; ++k) r += w[k] * rk[k][s], rx += w[k] * gk[k][s], ry += dw[k] * rk[k][s];
    const double e = l[s] - gain * r - offset;
    t.sxx += rx * rx, t.sxy += rx * ry, t.sxr += rx * r, t.sx += rx;
    t.syy += ry * ry, t.syr += ry * r, t.sy += ry;
    t.srr += r * r, t.sr += r;
    t.sxe += rx * e, t.sye += ry * e, t.sre += r * e, t.se += e;
    t.slr += l[s] * r;
  }
  return t;
}

TEST(RowOffsetSums, EqualThePlainLoopBitForBit) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> intensity(0, 255), slope(-40, 40);
  std::uniform_real_distribution<double> t01(0, 1), near1(0.5, 1.5), level(-20, 20);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + trial % 120, npad = (n + 7) / 8 * 8;
    std::vector<float> buffer(9 * size_t(npad));
    for (float& v : buffer) v = intensity(rng);
    const float* l = buffer.data();
    const float* rk[4];
    const float* gk[4];
    for (int k = 0; k < 4; ++k) {
      float* g = buffer.data() + (2 + 2 * k) * size_t(npad);
      for (int s = 0; s < npad; ++s) g[s] = slope(rng);
      rk[k] = buffer.data() + (1 + 2 * k) * size_t(npad), gk[k] = g;
    }
    // Cubic-like weights: any values exercise the arithmetic.
    const double t = t01(rng);
    const double w[4] = {-0.5 * t * (1 - t) * (1 - t), 1 - 2.5 * t * t, 0.5 * t + 2 * t * t, -0.5 * t * t * (1 - t)};
    const double dw[4] = {t01(rng) - 0.5, -5 * t, 0.5 + 4 * t, -t};
    const double gain = near1(rng), offset = level(rng);
    const RowOffsetSums expected = PlainSums(l, rk, gk, w, dw, gain, offset, n);
    ASSERT_EQ(RowOffsetPassSums(l, rk, gk, w, dw, gain, offset, n), expected) << "n " << n;
  }
}

}  // namespace
}  // namespace stereorig
