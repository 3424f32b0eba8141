// A rigid transform as a file gives it: a 4x4 matrix of printed numbers.
//
// The project's writers print %.17g, whose rotations are orthonormal to
// ~1e-16; a rotation copied by hand, or from a tool that prints 8
// significant digits, is orthonormal only to ~1e-8 (0.10452110 for
// 0.10452110486450766 leaves |R^T R - I| at 1e-9), which a 1e-9 tolerance
// refused with nothing to fix but the digits. Such a rotation is off by
// ~1e-8 rad, a hundredth of a micrometre at a metre: re-orthonormalised
// within kTypedRotationTolerance, it costs no measurement. Beyond, the
// numbers are wrong, not rounded, and are refused.
#pragma once

#include <Eigen/Core>
#include <string>

#include "calib/core/pose.h"

namespace stereorig {

// |R^T R - I| (max element) up to which a typed rotation is taken as
// rounded, and replaced by the nearest rotation: 2e-6, what every rotation
// typed with 6 significant digits meets. Each element of R is at most 1,
// so 6 digits round it by at most e = 5e-7; an element of R^T R - I then
// moves by at most 2 (|r_1| + |r_2| + |r_3|) e + 3 e^2 <= 2 sqrt(3) e =
// 1.73e-6 for a unit column (1e-6, the first bound, refused some).
inline constexpr double kTypedRotationTolerance = 2e-6;

// `m` as a Pose: as it is where it is rigid to 1e-9 (so that a file written
// by the project reads back bit for bit); the nearest rotation (SVD) to its
// block, the bottom row (0 0 0 1), where it is rigid to
// kTypedRotationTolerance; else throws InputError(`where`, why), with the
// deviation and the tolerance.
Pose TypedRigidPose(const Eigen::Matrix4d& m, const std::string& where);

}  // namespace stereorig
