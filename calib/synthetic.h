// A synthetic capture generator for the engine's tests: it places a target at
// random poses in a rig's measurement volume, projects every corner through
// the TRUE cameras (Camera::Project) and adds Gaussian pixel noise. Faces
// follow physics: a camera sees the face whose side it is on, and only the
// corners that land on its imager (partial views).
#pragma once

#include <functional>
#include <random>
#include <vector>

#include "calib/core/rig.h"
#include "calib/observations.h"

namespace stereorig {

struct SyntheticOptions {
  int num_captures = 25;  // default 25
  double noise_px = 0.2;  // 1 sigma per pixel coordinate; default 0.2
  unsigned seed = 1;
  double max_tilt_deg = 35.0;   // board tilt about its x and y axes, uniform in +-; default 35
  double max_roll_deg = 20.0;   // about the board normal; default 20
  double lateral_mm = 25.0;     // board centre offset across the volume, uniform in +-; default 25
  double depth_mm = 30.0;       // along the volume's z, uniform in +-; default 30
  int min_corners = 8;          // a view with fewer corners on the imager is dropped; default 8
  double edge_margin_px = 2.0;  // corners this close to the imager edge are not detected; default 2
};

struct SyntheticData {
  CalibrationInput input;
  std::vector<Pose> ref_from_front;  // (num_captures,) true board poses
};

// `ref_from_volume`: the measurement volume's centre and axes in the rig's
// reference frame; at tilt 0 the board's front face lies in the volume's xy
// plane facing -z (its own z along the volume's z). `target` is what the
// engine is told; `true_back_from_front` is how the board really is.
SyntheticData MakeSyntheticCaptures(const Rig& rig, const TargetGeometry& target, const Pose& true_bff,
                                    const Pose& ref_from_volume, const SyntheticOptions& o);

// The corners of boards at the given poses (`ref_from_front`, one per
// capture), seen through the TRUE cameras with the noise, margin and
// minimum corner count of `o` (its pose fields are unused). A camera sees the
// face its centre is in front of. `true_corner_in_front(face, id)`: where
// that corner really is, in the front face's frame (mm) - the nominal corner
// for a perfect board; a scaled, bowed or misaligned one for a study of those.
using TrueCornerInFront = std::function<Eigen::Vector3d(Face face, int id)>;
SyntheticData ObserveBoards(const Rig& rig, const TargetGeometry& target, const std::vector<Pose>& ref_from_front,
                            const TrueCornerInFront& true_corner_in_front, const SyntheticOptions& o);

// Points filling a box (mm, half-sizes) around `ref_from_volume`, in the
// reference frame: for the 3D accuracy checks.
std::vector<Eigen::Vector3d> VolumePoints(const Pose& ref_from_volume, const Eigen::Vector3d& half_size_mm, int n,
                                          unsigned seed);

// The default test target: 9x7 inner corners, 12 mm squares, double-sided.
TargetGeometry DefaultTestTarget();

}  // namespace stereorig
