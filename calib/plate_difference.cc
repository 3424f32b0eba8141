#include "calib/plate_difference.h"

#include <cmath>

namespace stereorig {

const char* PlateAxisName(int axis) {
  static const char* const kAxis[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  return kAxis[axis];
}

const char* PlateAxisUnit(int axis) { return axis < 3 ? "deg" : "mm"; }

Eigen::Vector3d PlateTurnDeg(const Pose& a, const Pose& b) {
  return Pose(a.rotation() * b.rotation().transpose(), Eigen::Vector3d::Zero()).RotationVector() * 180.0 / M_PI;
}

double SamePlateChiSquare(int axes) {
  // The 99.73 % quantiles of chi-square with 1..6 degrees of freedom.
  static const double kQuantile[7] = {0.0, 9.00, 11.83, 14.16, 16.25, 18.21, kSamePlateChiSquare};
  return kQuantile[axes < 0 ? 0 : axes > 6 ? 6 : axes];
}

PlateDifference ComparePlates(const Eigen::Matrix<double, 6, 1>& off, const Eigen::Matrix<double, 6, 1>& variance) {
  PlateDifference d;
  double worst_chi = -1;
  for (int k = 0; k < 6; ++k) {
    const double s2 = variance(k);
    if (s2 == 0) {
      if (std::abs(off(k)) >= kPlateUnchangedInPrint && d.held_moved < 0) d.held_moved = k;
      continue;
    }
    d.chi_square += off(k) * off(k) / s2;
    ++d.axes;
    if (off(k) * off(k) / s2 > worst_chi) {
      worst_chi = off(k) * off(k) / s2;
      d.worst = k;
      d.worst_off = off(k);
      d.worst_sigma = std::sqrt(s2);
    }
  }
  return d;
}

}  // namespace stereorig
