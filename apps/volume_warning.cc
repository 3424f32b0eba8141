#include "apps/volume_warning.h"

#include <cstdio>

#include "reconstruct/score.h"

namespace stereorig {

double WarnIfVolumeMissesTruth(const std::string& command, const std::string& scene,
                               const std::vector<Eigen::Vector3d>& truth_surface_mm,
                               const Eigen::Vector3d& volume_center_mm, const Eigen::Vector3d& volume_size_mm) {
  const double inside = ShareInsideBox(truth_surface_mm, volume_center_mm, volume_size_mm);
  if (inside >= 0.5 || truth_surface_mm.empty()) return inside;
  Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : truth_surface_mm) centroid_mm += p / double(truth_surface_mm.size());
  std::fprintf(stderr,
               "%s: the measurement volume holds %.0f%% of %s's truth surface: its centre is %.0f mm from module 0, "
               "the scene's %.0f mm; set working_distance_mm (or volume_center_mm) in --options\n",
               command.c_str(), 100 * inside, scene.c_str(), volume_center_mm.norm(), centroid_mm.norm());
  return inside;
}

}  // namespace stereorig
