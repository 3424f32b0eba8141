// Which target corner each corner of an OpenCV grid is: the map from OpenCV's
// grid index (c, r) to the face's (col, row), decided from the tags (a
// double-sided target) or from the board's shape and colours (a plain one).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "targets/chessboard_grid.h"
#include "targets/tag_detect.h"
#include "targets/target.h"

namespace stereorig {

// face (col, row) = d * (c, r) + offset, d one of the 8 symmetries of the
// square (OpenCV's grid may come in either handedness).
struct GridMap {
  Eigen::Matrix2i d = Eigen::Matrix2i::Identity();
  Eigen::Vector2i offset = Eigen::Vector2i::Zero();
  Eigen::Vector2i operator()(int c, int r) const { return d * Eigen::Vector2i(c, r) + offset; }
};

struct GridIds {
  bool ok = false;
  std::string problem;  // why not, when !ok
  GridMap map;
  std::vector<bool> keep;     // (rows * cols) corners that agree with the map
  double tag_fit_rms_px = 0;  // tags only
};

// Homography image_from_face (face mm, z = 0 -> px) through the tags'
// corners. False (with *problem) if they fit none, appear mirrored or
// disagree by more than `max_fit_squares` RMS.
bool TagHomography(const Target& target, Face face, const std::vector<TagDetection>& tags, double max_fit_squares,
                   Eigen::Matrix3d* image_from_face, std::string* problem, bool* mirrored);

// Ids by the tags: each grid corner, taken to the face frame by the tags'
// homography, must land within `gate_squares` of a corner id, consistently
// for one symmetry and offset, for at least `min_agreeing_fraction` of them.
GridIds GridIdsFromTags(const Target& target, Face face, const std::vector<TagDetection>& tags,
                        const Eigen::Matrix3d& image_from_face, const ChessboardGrid& grid, double gate_squares,
                        double min_agreeing_fraction);

// Ids of a plain board seen whole: among the symmetries that map the grid
// onto the board and keep the image's handedness, the one whose expected
// square colours match `grey`; among colour twins, the one whose face x axis
// points most to the image's right (docs/targets.md, "Plain boards").
GridIds GridIdsFromColours(const Target& target, const cv::Mat& grey, const ChessboardGrid& grid);

}  // namespace stereorig
