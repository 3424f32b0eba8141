// One camera's view of one face of the target in one capture: detected
// corners with their IDs in that face's frame. This is what detection
// produces and what the check consumes.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "targets/target.h"

namespace stereorig {

struct CornerView {
  int capture = 0;
  int camera = 0;                        // global camera index
  Face face = Face::kFront;
  std::vector<int> corner_ids;           // (N) ids in the face frame
  std::vector<Eigen::Vector2d> q_px;     // (N) mrcal pixel convention
};

}  // namespace stereorig
