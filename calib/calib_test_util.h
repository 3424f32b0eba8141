// Truth-based measures for the engine's tests. Everything here compares a
// calibration with the TRUE rig, by the users' own figures, with independent
// tools (Eigen's Umeyama for rigid alignment).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "calib/core/camera.h"
#include "calib/core/pose.h"
#include "calib/core/rig.h"
#include "calib/rig_compare.h"

namespace stereorig::testing {

using stereorig::ModuleAgreementRms;
using stereorig::RigidAlignedRms;
using stereorig::TriangulateThroughModule;

// The default rig's measurement volume in module 0's frame: the world origin,
// world axes (module 0 looks along world +z).
Pose DefaultVolume(const Pose& world_from_module0);

// mrcal's "mean-frames" projection error against the truth: the point the true
// camera sees at q_px at range_mm is carried into every board frame with the
// TRUE board poses, back into the camera with the SOLVED poses, averaged, and
// projected with the solved camera. Returns the projected - q_px (px).
Eigen::Vector2d MeanFramesProjectionError(const Camera& truth, const std::vector<Pose>& true_cam_from_face,
                                          const Camera& solved, const std::vector<Pose>& solved_cam_from_face,
                                          const Eigen::Vector2d& q_px, double range_mm);

}  // namespace stereorig::testing

#include "calib/synthetic.h"
#include "datasets/default_rig.h"

namespace stereorig::testing {

// The captures in which two cameras both observed the board (a view with
// corners in `in`) and the TRUE board's plane (front face at
// ref_from_front[capture], reference frame) passes between their centres:
// those in which they saw different faces, judged from the truth's geometry
// alone, not from the faces the observations carry (nor from calib's
// bookkeeping, which the tests check against it). Sorted.
std::vector<int> CapturesWhoseBoardPlaneSeparates(const Rig& truth, const std::vector<Pose>& ref_from_front,
                                                  const CalibrationInput& in, int camera_a, int camera_b);

// The observations camera `cam` made, in capture order (pointers into `in`).
std::vector<const BoardObservation*> ViewsOf(const CalibrationInput& in, int cam);

// The default rig with `captures` synthetic captures of the default test
// target at `noise_px`. The engine is told a back_from_front that differs
// from the true one by a draw from its stated 1 sigma, as a measured one would.
struct DefaultScene {
  SimulatedRig truth;
  Pose ref_from_volume;
  Pose true_back_from_front;
  SyntheticData data;
};
DefaultScene MakeDefaultScene(unsigned seed, int captures, double noise_px);
// The same for any simulated rig whose volume sits at the world origin.
DefaultScene MakeScene(const SimulatedRig& rig, unsigned seed, int captures, double noise_px);

// Variants of the default rig for the module-count tests: module 0 alone, and
// the default two plus a third module beside module 0, turned 30 deg about
// the world's y axis (it sees the front face, as module 0 does).
SimulatedRig MakeOneModuleRig();
SimulatedRig MakeThreeModuleRig();

}  // namespace stereorig::testing
