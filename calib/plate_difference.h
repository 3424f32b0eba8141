// How far two estimates of one plate's back_from_front are apart, judged by
// their sigmas: a chi-square over the six axes. Two users of one test:
//  - calibrate's stage 3 refines the target file's back_from_front under
//    the file's stated sigma; a refined plate far beyond it says the file is
//    not this plate's (a thickness typed in metres: tz 0.005 refined to
//    4.99 mm, 500 sigma), and the rig file is not written (calibrate.h);
//  - the nightly check compares tonight's target file with the one filed at
//    calibration (calib/check/check_target.h): another plate is refused.
#pragma once

#include <Eigen/Core>

#include "calib/core/pose.h"

namespace stereorig {

// The chi-square (6 axes) beyond which two estimates are not of one plate:
// the 99.73 % quantile of chi-square with 6 degrees of freedom (3 sigma's
// two-sided coverage), so 3 of 1000 honest pairs are taken for another
// plate.
inline constexpr double kSamePlateChiSquare = 20.06;

// The same quantile over `axes` (0..6) judged axes: an axis held (sigma 0,
// known exactly) adds nothing to the chi-square, so the bound is the one of
// the axes left (1: 9.00 ... 6: kSamePlateChiSquare); 0 with none.
double SamePlateChiSquare(int axes);

// What %.4f prints as 0, mm or deg: an axis both sigmas hold (0) may move
// by less and still count as held.
inline constexpr double kPlateUnchangedInPrint = 5e-5;

// The axes' names in the order of back_from_front_sigma: rx, ry, rz (deg),
// tx, ty, tz (mm); and their units.
const char* PlateAxisName(int axis);
const char* PlateAxisUnit(int axis);

// The turn from `b` to `a` about the axes as stage 3 perturbs
// back_from_front: the rotation vector of R_a R_b^T, deg.
Eigen::Vector3d PlateTurnDeg(const Pose& a, const Pose& b);

// off: (6,) the difference per axis [rx, ry, rz (deg), tx, ty, tz (mm)];
// variance: (6,) its variance per axis (deg^2, mm^2), 0 for an axis held.
struct PlateDifference {
  double chi_square = 0;   // over the axes whose variance is > 0
  int axes = 0;            // how many: the chi-square's degrees of freedom
  int held_moved = -1;     // the first held axis that moved (>= kPlateUnchangedInPrint), or -1
  int worst = 0;           // the axis adding most to chi_square
  double worst_off = 0;    // its difference (deg or mm)
  double worst_sigma = 0;  // its sigma, the square root of its variance
  // Within SamePlateChiSquare(axes) and no held axis moved.
  bool SamePlate() const { return held_moved < 0 && chi_square <= Bound(); }
  double Bound() const { return SamePlateChiSquare(axes); }
};
PlateDifference ComparePlates(const Eigen::Matrix<double, 6, 1>& off, const Eigen::Matrix<double, 6, 1>& variance);

}  // namespace stereorig
