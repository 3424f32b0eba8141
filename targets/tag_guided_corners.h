// Corners found from the tags outwards, for views where OpenCV's grid search
// fails or returns a wrong grid (a board running out of the image, steep
// tilts): each corner id's pixel is predicted by a homography through the
// tags (and the corners found so far), refined with cv::cornerSubPix, and
// kept only if the image around it shows the chessboard saddle with the
// colours the target says. The set grows outwards until nothing is added.
#pragma once

#include <Eigen/Core>
#include <vector>

#include <opencv2/core.hpp>

#include "targets/chessboard_grid.h"
#include "targets/tag_detect.h"
#include "targets/target.h"

namespace stereorig {

struct TagGuidedCorners {
  std::vector<int> ids;               // (N) ascending
  std::vector<Eigen::Vector2d> q_px;  // (N), mrcal pixel convention
  double tag_fit_rms_px = 0;          // tags' corners against the final homography
};

// `image_from_face`: the tags' homography (grid_ids.h TagHomography).
// Refinement windows follow `refine` (its fraction, min and max half sizes).
TagGuidedCorners FindCornersFromTags(const Target& target, Face face, const std::vector<TagDetection>& tags,
                                     const Eigen::Matrix3d& image_from_face, const cv::Mat& grey,
                                     const ChessboardGridOptions& refine);

}  // namespace stereorig
