// Detection of a target face in one grey image: which face is seen, and each
// visible chessboard corner's id in that face's own frame, at sub-pixel
// precision (docs/targets.md, "Detection").
//
// A double-sided target: the AprilTags of one face say which face it is;
// a homography from their corners (face frame, mm) to the image predicts
// each corner id's pixel, and the corners are grown out from the tags
// (tag_guided_corners.h), each refined with cv::cornerSubPix and checked to
// be a saddle of the right colours. Optionally OpenCV's whole-board grid is
// tried first and its ids decided by the tags (grid_ids.h). Partial boards
// work as long as one tag is seen. A plain board (no tags): OpenCV's
// findChessboardCornersSB on the whole board, which must be visible; the
// ids follow from the board's shape, the colours of its squares and, where
// those are symmetric, the image's right direction (docs/targets.md).
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
  // Tagged targets: run OpenCV's whole-board search when the tags say the
  // whole board is in view (its grid is then checked against the tags), and
  // grow corners out from the tags only where it fails. Default false:
  // measured on 60 rendered views of the default target (250-360 mm, tilts
  // to 40 deg, 1 DN noise), growing from the tags alone found the same
  // corners (5920 of 5925 in view) at the same RMS (0.036 px) in a fifth of
  // the time (0.08 s vs 0.4 s per image on this 2-core machine). Plain
  // boards always use OpenCV's search.
  bool opencv_whole_board = false;
  // After the whole-board search, also try OpenCV's partial-board search
  // (CALIB_CB_LARGER) before growing corners out from the tags. Default
  // false: on rendered partial views of the default target it often locks
  // onto a wrong grid (every other corner, or the board's outer edge), which
  // the tags then reject; tag-guided growth finds those views' corners.
  bool opencv_partial_search = false;
  // Fewest corners a detection may keep; fewer -> rejected. Default 12.
  int min_corners = 12;
  // Smallest corner grid (each way) OpenCV's partial-board search accepts.
  // Default 3.
  int min_partial_grid = 3;
  // A grid corner is given the id the tags predict for it only if it lies
  // within this distance of that id's predicted position, in squares.
  // Default 0.3 (the wrong neighbour is 1 square away).
  double id_gate_squares = 0.3;
  // Fraction of the grid's corners that must agree with the tags' prediction;
  // fewer -> rejected as inconsistent. Default 0.9.
  double min_agreeing_fraction = 0.9;
  // The tags' corners must fit one board homography to within this RMS, in
  // squares, and each tag must sit within it of where the detected corners
  // put it; else the view is rejected as ambiguous (a damaged print or a
  // wrong target file). Default 0.25.
  double max_tag_fit_squares = 0.25;
  // If set, a detection of the other face is rejected ("wrong face").
  std::optional<Face> expected_face;
  void Check() const;  // throws InputError naming the bad field
};

// How the corners were found.
enum class CornerSource {
  kNone,
  kOpenCvGrid,  // cv::findChessboardCornersSB's grid (whole or partial board), ids from tags or colours
  kTagGuided,   // grown out from the tags (tag_guided_corners.h)
};
const char* CornerSourceName(CornerSource source);

// How good one detection is.
struct DetectionQuality {
  CornerSource source = CornerSource::kNone;
  int num_corners = 0;               // corners kept
  int grid_cols = 0, grid_rows = 0;  // size of OpenCV's corner grid
  int num_tags = 0;                  // tags of the detected face used
  std::vector<int> tag_ids;          // their IDs
  int num_foreign_tags = 0;          // decoded tags whose IDs are not on this target
  // The tags' corners against the homography fitted to the detected
  // chessboard corners alone (face mm -> px): RMS over all tags, and the
  // worst tag's RMS, px. A tag off by more than max_tag_fit_squares of a
  // square rejects the view (a wrong target file or a damaged print). 0 for
  // a plain board.
  double tag_fit_rms_px = 0;
  double worst_tag_fit_px = 0;
  // Each corner with all 8 grid neighbours found is predicted from them by a
  // local homography; the RMS of (detected - predicted), px. Noise-like:
  // about 1.1x the per-corner noise for sharp corners, insensitive to lens
  // distortion. NaN if no corner has 8 neighbours.
  double local_fit_rms_px = 0;
  int local_fit_count = 0;  // corners that entered local_fit_rms_px
  int num_dropped = 0;      // grid corners dropped by the refinement (at the image's edge, slid off)
  // OpenCV's edge-rise width and levels over the largest complete block of
  // corners found; NaN when no 3x3 block is complete.
  ChessboardSharpness sharpness;
};

// With refinement on (the default), every corner returned was refined in a
// window wholly inside the image and moved less than that window's half
// size, so it lies at least 2 px inside the image.
struct FaceDetection {
  Face face = Face::kFront;
  std::vector<int> corner_ids;        // (N) ascending; ids in `face`'s frame (Target::CornerInFace)
  std::vector<Eigen::Vector2d> q_px;  // (N) parallel to corner_ids
  DetectionQuality quality;
};

enum class RejectReason {
  kNone,           // accepted
  kNoChessboard,   // no corner grid found
  kNoTags,         // double-sided target, but no tag of it seen
  kBothFaces,      // tags of both faces: which face is it?
  kWrongFace,      // not DetectOptions::expected_face
  kMirrored,       // the board appears mirrored
  kAmbiguous,      // tags disagree, or the grid fits no single orientation
  kGridMismatch,   // the grid does not fit this target (size, corners outside)
  kTooFewCorners,  // fewer than DetectOptions::min_corners
};
const char* RejectReasonName(RejectReason reason);

struct DetectResult {
  std::vector<FaceDetection> faces;  // at most one: a camera sees one face
  RejectReason reason = RejectReason::kNone;
  std::string message;       // why it was rejected, for people
  DetectionQuality quality;  // what was measured, even when rejected
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
