// Detection of a target face in one grey image: which face is seen, and each
// visible chessboard corner's id in that face's own frame, at sub-pixel
// precision (docs/targets.md, "Detection").
//
// A double-sided target: OpenCV finds a (possibly partial) corner grid; the
// AprilTags of one face say which face it is and, through a homography from
// their corners (face frame, mm) to the image, which corner id each grid
// corner is. A plain board (no tags): the whole board must be visible; the
// ids follow from the board's shape, the colours of its squares and, where
// those are symmetric, the image's up direction (docs/targets.md).
//
// Pixels follow mrcal: (0,0) is the centre of the top-left pixel.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "targets/chessboard_grid.h"
#include "targets/tag_detect.h"
#include "targets/target.h"

namespace stereorig {

struct DetectOptions {
  ChessboardGridOptions chessboard;  // corner finding and refinement
  TagDetectOptions tags;             // AprilTag detection
  // Fewest corners a detection may keep; fewer -> rejected. Default 12.
  int min_corners = 12;
  // Smallest corner grid (each way) the partial-board search accepts.
  // Default 3 (a 3x3 patch of corners next to one tag is usable).
  int min_partial_grid = 3;
  // A grid corner is given the id the tags predict for it only if it lies
  // within this distance of that id's predicted position, in squares.
  // Default 0.3 (the wrong neighbour is 1 square away).
  double id_gate_squares = 0.3;
  // Fraction of the grid's corners that must agree with the tags' prediction;
  // fewer -> rejected as inconsistent. Default 0.9.
  double min_agreeing_fraction = 0.9;
  // The tags' corners must fit one board homography to within this RMS, in
  // squares; else the tags disagree (a damaged or wrong target). Default 0.25.
  double max_tag_fit_squares = 0.25;
  // If set, a detection of the other face is rejected ("wrong face").
  std::optional<Face> expected_face;
  void Check() const;  // throws InputError naming the bad field
};

// How good one detection is.
struct DetectionQuality {
  int num_corners = 0;              // corners kept
  int grid_cols = 0, grid_rows = 0; // size of OpenCV's corner grid
  int num_tags = 0;                 // tags of the detected face used
  std::vector<int> tag_ids;         // their IDs
  int num_foreign_tags = 0;         // decoded tags whose IDs are not on this target
  // RMS distance of the tags' corners from the homography fitted to tags and
  // corners together, px. 0 for a plain board.
  double tag_fit_rms_px = 0;
  // Each corner with all 8 grid neighbours found is predicted from them by a
  // local homography; the RMS of (detected - predicted), px. Noise-like:
  // about 1.1x the per-corner noise for sharp corners, insensitive to lens
  // distortion. NaN if no corner has 8 neighbours.
  double local_fit_rms_px = 0;
  int local_fit_count = 0;          // corners that entered local_fit_rms_px
  int num_refine_rejected = 0;      // corners left at OpenCV's own estimate
  ChessboardSharpness sharpness;    // OpenCV's edge-rise width and levels
};

struct FaceDetection {
  Face face = Face::kFront;
  std::vector<int> corner_ids;          // (N) ascending; ids in `face`'s frame (Target::CornerInFace)
  std::vector<Eigen::Vector2d> q_px;    // (N) parallel to corner_ids
  DetectionQuality quality;
};

enum class RejectReason {
  kNone,             // accepted
  kNoChessboard,     // no corner grid found
  kNoTags,           // double-sided target, but no tag of it seen
  kBothFaces,        // tags of both faces: which face is it?
  kWrongFace,        // not DetectOptions::expected_face
  kMirrored,         // the board appears mirrored
  kAmbiguous,        // tags disagree, or the grid fits no single orientation
  kGridMismatch,     // the grid does not fit this target (size, corners outside)
  kTooFewCorners,    // fewer than DetectOptions::min_corners
};
const char* RejectReasonName(RejectReason reason);

struct DetectResult {
  std::vector<FaceDetection> faces;  // at most one: a camera sees one face
  RejectReason reason = RejectReason::kNone;
  std::string message;               // why it was rejected, for people
  DetectionQuality quality;          // what was measured, even when rejected
};

// Holds the AprilTag detector, so detecting many images costs no set-up.
// Not thread-safe: use one per thread.
class TargetDetector {
 public:
  TargetDetector(const Target& target, const DetectOptions& options);
  // `grey`: CV_8UC1, any size.
  DetectResult Detect(const cv::Mat& grey) const;
  const Target& target() const { return target_; }

 private:
  Target target_;
  DetectOptions options_;
  TagDetector tags_;
};

// The entry point for one image: the detected face(s) (empty when rejected,
// with the reason in *why_rejected, which may be null).
std::vector<FaceDetection> DetectTarget(const cv::Mat& grey, const Target& target, const DetectOptions& options,
                                        std::string* why_rejected);

}  // namespace stereorig
