// Correlating float rows with a short kernel, along a row or down the
// columns of a stack of rows, by the arithmetic cv::filter2D (CV_32F,
// BORDER_CONSTANT 0) uses on a CPU with FMA: each output is the chain
// s = fma(sample, tap, s) over the kernel's nonzero taps in order, from
// s = 0, where a sample beyond the ends is 0 and so leaves s as it is (up to
// the sign of a zero sum, which no later step of the surface fit can tell).
//
// Why not filter2D: the surface fit (local_surface_fit.h) ran 31 of them per
// band of 128 rows, 310 per capture on the demo cup, and OpenCV's set-up,
// row copies into a bordered ring buffer and per-row dispatch cost about as
// much as the multiply-adds. These compute the same sums bit for bit
// (kernel_correlation_test.cc checks them against filter2D); the chain is
// written out with std::fma, so they give the same sums on any CPU, where
// filter2D without FMA rounds each product apart.
#pragma once

#include <vector>

namespace stereorig {

// A kernel of 2 half + 1 taps, kept as its nonzero taps and their offsets
// from the centre, in order (filter2D skips zero taps; so do these).
struct KernelTaps {
  std::vector<float> value;
  std::vector<int> offset;  // in [-half, half], increasing
};
// taps: 2 half + 1 values, centre at taps[half].
KernelTaps NonzeroTaps(const float* taps, int half);

// out[x] = sum over the taps of value * in[x + offset], x in [0, width);
// in[] beyond [0, width) is 0. in and out must not overlap.
void CorrelateAlongRow(const float* in, int width, const KernelTaps& taps, float* out);

// out[x] = sum over the taps of value * in(y + offset, x), x in [0, width),
// for row y of a stack of `rows` rows of `width` floats, `stride` floats
// apart (in(r, x) = in[r * stride + x]); rows beyond [0, rows) are 0.
// out must not overlap in.
void CorrelateDownColumns(const float* in, long stride, int rows, int y, int width, const KernelTaps& taps, float* out);

}  // namespace stereorig
