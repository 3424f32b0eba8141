// The warning of `score` and `bench` when the measurement volume misses a
// scene of a simulator dataset: a volume that holds little of the object
// gives empty clouds, which must not pass silently (docs/reconstruct.md,
// "the range"). A warning, so on stderr: stdout carries the results.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

// Returns the share, in [0, 1], of `truth_surface_mm` (N samples in the
// truth frame, module 0's) inside the measurement volume (`volume_center_mm`,
// `volume_size_mm`: the runtime's). Below one half, prints one line on stderr
// naming `command` and `scene`, the volume's and the scene's distances from
// module 0, and the keys that move the volume. Nothing for an empty surface.
double WarnIfVolumeMissesTruth(const std::string& command, const std::string& scene,
                               const std::vector<Eigen::Vector3d>& truth_surface_mm,
                               const Eigen::Vector3d& volume_center_mm, const Eigen::Vector3d& volume_size_mm);

}  // namespace stereorig
