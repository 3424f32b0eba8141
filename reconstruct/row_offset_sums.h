// The window sums of one Gauss-Newton pass of the line index's 4-parameter
// fit (RefineDisparityAndRowOffset, subpixel_refine.h): the right sample of
// each window pixel blended over 4 rows with cubic weights, its slopes
// along x and y, and the sums of their products that give J^T J and J^T e.
//
// Apart from row_offset_refine.cc because that file solves with Eigen and
// must not be built with -march=native (reconstruct/CMakeLists.txt); this
// one is, and without FP contraction (-ffp-contract=off), so that its AVX2
// path does every sample's arithmetic as the plain loop does, operation for
// operation in double: the blend 4 samples at a time, each sum accumulated
// in sample order with the 14 sums spread over the lanes of 4 registers.
// Bit-equal to the plain loop (row_offset_sums_test.cc); it was ~55 % of
// the line index's cost at speckle 0.4 (callgrind, sp_high plate).
#pragma once

namespace stereorig {

// Sums over the samples s < n, with J = (gain rx, -gain ry, -r, -1) and
// e = l - gain r - offset, r = sum_k w[k] rk[k][s], rx = sum_k w[k] gk[k][s],
// ry = sum_k dw[k] rk[k][s] (k = 0..3, summed in that order from 0).
struct RowOffsetSums {
  double sxx = 0, sxy = 0, sxr = 0, sx = 0;  // rx rx, rx ry, rx r, rx
  double syy = 0, syr = 0, sy = 0;           // ry ry, ry r, ry
  double srr = 0, sr = 0;                    // r r, r
  double sxe = 0, sye = 0, sre = 0, se = 0;  // rx e, ry e, r e, e
  double slr = 0;                            // l r
  bool operator==(const RowOffsetSums&) const = default;
};

// l: the left values, rk[k] / gk[k]: row k's right samples and their slopes
// along x; each readable up to n rounded up to a multiple of 8 (the
// window's padded size, subpixel_window.h); w, dw: the rows' cubic weights
// and their derivatives.
RowOffsetSums RowOffsetPassSums(const float* l, const float* const rk[4], const float* const gk[4], const double w[4],
                                const double dw[4], double gain, double offset, int n);

}  // namespace stereorig
