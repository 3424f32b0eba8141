// AprilTag detection on a grey image, restricted to one target's tags.
//
// Wraps libapriltag (AprilTag 3). A TagDetector owns the C detector and its
// family; it is not safe to call Detect() from two threads at once (use one
// detector per thread).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "targets/target.h"

namespace stereorig {

struct TagDetectOptions {
  // Quad detection on an image decimated by this factor (1 = full resolution).
  // Decoding always uses full resolution. Default 1: the tags of the default
  // target are only ~55 px wide at 200 mm on a 752x582 camera.
  double decimate = 1.0;
  // Gaussian blur (sigma, px) before quad detection; 0 = none. Default 0.
  double blur_sigma_px = 0.0;
  // Most bit errors corrected per tag. Default 1: tag36h11 has Hamming
  // distance 11, so 1 keeps false positives negligible.
  int max_bit_errors = 1;
  // Weakest decision margin (mean |bit intensity - threshold|, grey levels)
  // accepted. Default 20.
  double min_decision_margin = 20.0;
  void Check() const;  // throws InputError naming the bad field
};

// One detected tag that belongs to the target.
struct TagDetection {
  int id = 0;
  Face face = Face::kFront;
  // Outer corners of the black border, px, mrcal convention ((0,0) = centre
  // of the top-left pixel), in libapriltag's order: p[0] is the tag's
  // bottom-left, then bottom-right, top-right, top-left (TagCornersInFace()
  // gives the same four in the face frame).
  std::array<Eigen::Vector2d, 4> q_px;
  int bit_errors = 0;
  double decision_margin = 0.0;
};

// The four outer corners of `tag` in its face frame (mm, z = 0), in
// libapriltag's order (see TagDetection::q_px). The tag is printed with its
// rows along the face's +y: its "bottom" edge is at larger y.
std::array<Eigen::Vector2d, 4> TagCornersInFace(const Target& target, const TagPlacement& tag);

class TagDetector {
 public:
  TagDetector(const Target& target, const TagDetectOptions& options);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  // `grey`: CV_8UC1. Returns the target's tags found (tags of other IDs are
  // counted in *num_foreign, which may be null). A target without tags
  // returns nothing.
  std::vector<TagDetection> Detect(const cv::Mat& grey, int* num_foreign = nullptr) const;

 private:
  struct Impl;
  Target target_;
  TagDetectOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stereorig
