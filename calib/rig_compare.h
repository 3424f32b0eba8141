// Judging a calibrated rig against a true one (a simulated dataset's
// truth/rig.yaml) by the figures users measure with, not by single
// parameters:
//   - a module's 3D error: points of the volume projected through the TRUE
//     cameras without noise, triangulated with the calibrated module, compared
//     with the true points after the best rigid alignment (no scale);
//   - module agreement: the same point triangulated by modules i and j, j's
//     mapped through the calibrated S[i][j], RMS distance.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/core/pose.h"
#include "calib/core/rig.h"

namespace stereorig {

// Why `truth` cannot judge `calibrated` module by module, or "" if it can:
// the two need as many modules and cameras, and each module of `calibrated`
// a module of `truth` with the same left and right cameras (in any order of
// the modules: a layout may list them in another). Names the first module
// whose cameras no module of the truth has, and says so where the truth's
// has them with left and right swapped. Compared index by index, a layout's
// reordered modules were judged against each other's truth (3D errors of
// 1 mm for a right rig), and a swapped pair saw no point of the volume.
std::string TruthModuleMismatch(const Rig& calibrated, const Rig& truth);

// `truth` with its modules in `calibrated`'s order, each matched by its
// cameras (TruthModuleMismatch passed), S expressed for that order: its
// reference is then the module `calibrated` lists first. The figures below
// compare module k with module k, so they take a truth in this order.
Rig TruthInModuleOrderOf(const Rig& calibrated, const Rig& truth);

// Triangulates each true point (reference frame) with module k of `calibrated`
// from its noise-free projections through the TRUE cameras of module k of
// `truth`. Points not seen by both cameras are skipped. Returns the points in
// the calibrated module frame, the matching true points in the true module
// frame, and (optionally) the indices of the points used.
void TriangulateThroughModule(const Rig& truth, const Rig& calibrated, int k, const std::vector<Eigen::Vector3d>& p_ref,
                              std::vector<Eigen::Vector3d>* p_calibrated, std::vector<Eigen::Vector3d>* p_true,
                              std::vector<int>* used = nullptr);

// RMS (mm) of a - (R b + t) after the best rigid alignment (no scale), by
// Eigen::umeyama.
double RigidAlignedRms(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b);

// Module agreement through S: RMS distance (mm) between points triangulated by
// module i and by module j (as above), module j's mapped through
// module_i_from_module_j. NaN if no point is seen by both modules.
double ModuleAgreementRms(const Rig& truth, const Rig& calibrated, const Pose& module_i_from_module_j, int i, int j,
                          const std::vector<Eigen::Vector3d>& p_ref);

}  // namespace stereorig
