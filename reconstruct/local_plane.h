// Growing's prediction (region_grow.h): the least-squares plane through the
// valid disparities around a pixel.
//
// It runs for every pixel growing tries (~20k per module on the demo cup)
// and once cost a third of growing's instructions: a 7x7 window scanned
// pixel by pixel and a 3x3 solve through Eigen's LDLT. Here the window's
// valid pixels come from a bitmap (validity_bits.h) and the solve is that
// LDLT written out for 3x3, with every floating-point operation in Eigen's
// order (built without FP contraction), so the result is bit for bit what
// the Eigen version gave (local_plane_test.cc checks it on random windows).
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/validity_bits.h"

namespace stereorig {

struct LocalPlane {
  double disparity_px = 0;  // at the pixel
  double slope_x = 0;       // dd/dx, px per px
  double slope_y = 0;       // dd/dy, px per px
};

// The plane d = a + gx (x - q.x) + gy (y - q.y) through the valid (finite)
// disparities of the (2r+1)^2 window around q, clipped to roi; r in
// [1, 10]. False (plane untouched) if fewer than 6 or degenerate (all on a
// line). disparity: CV_32FC1; valid: its validity over roi, in step with it.
bool FitLocalPlane(const cv::Mat& disparity, const ValidityBits& valid, const cv::Rect& roi, cv::Point q, int r,
                   LocalPlane* plane);

namespace internal {
// Solves m p = b for symmetric m (only its lower triangle, m[row][col] with
// row >= col, is read) as Eigen::LDLT<Matrix3d>(m).solve(b) does, bit for
// bit: diagonal pivoting, the pseudo-inverse of D below DBL_MIN.
void SolveLdlt3(const double m[3][3], const double b[3], double p[3]);
}  // namespace internal

}  // namespace stereorig
