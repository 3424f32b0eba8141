#include "targets/detect.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "calib/core/input_error.h"
#include "targets/grid_ids.h"
#include "targets/tag_guided_corners.h"

namespace stereorig {

void DetectOptions::Check() const {
  chessboard.Check();
  tags.Check();
  const std::string where = "target detection";
  if (min_corners < 4) throw InputError(where, "min_corners must be at least 4");
  if (min_partial_grid < 2) throw InputError(where, "min_partial_grid must be at least 2");
  if (!(id_gate_squares > 0 && id_gate_squares < 0.5)) throw InputError(where, "id_gate_squares must be in (0, 0.5)");
  if (!(min_agreeing_fraction > 0.5 && min_agreeing_fraction <= 1)) {
    throw InputError(where, "min_agreeing_fraction must be in (0.5, 1]");
  }
  if (!(max_tag_fit_squares > 0)) throw InputError(where, "max_tag_fit_squares must be positive");
}

const char* RejectReasonName(RejectReason reason) {
  switch (reason) {
    case RejectReason::kNone:
      return "none";
    case RejectReason::kNoChessboard:
      return "no_chessboard";
    case RejectReason::kNoTags:
      return "no_tags";
    case RejectReason::kBothFaces:
      return "both_faces";
    case RejectReason::kWrongFace:
      return "wrong_face";
    case RejectReason::kMirrored:
      return "mirrored";
    case RejectReason::kAmbiguous:
      return "ambiguous";
    case RejectReason::kGridMismatch:
      return "grid_mismatch";
    case RejectReason::kTooFewCorners:
      return "too_few_corners";
  }
  return "unknown";
}

namespace {

void Reject(DetectResult* out, RejectReason reason, const std::string& message) {
  out->faces.clear();
  out->reason = reason;
  out->message = message;
}

std::string IdList(const std::vector<TagDetection>& tags) {
  std::ostringstream o;
  for (size_t i = 0; i < tags.size(); ++i) o << (i ? "," : "") << tags[i].id;
  return o.str();
}

// The corner grids to try, in order: the whole board (the common case, and
// the most reliable search), then - for a tagged target, which may run out
// of the image - partial grids of decreasing minimum size. OpenCV's partial
// search sometimes locks onto a grid of every other corner; the tags then
// reject it and the next size is tried.
std::vector<std::pair<cv::Size, bool>> GridAttempts(const Target& target, const DetectOptions& options) {
  std::vector<std::pair<cv::Size, bool>> attempts = {{cv::Size(target.corners_x(), target.corners_y()), false}};
  if (target.double_sided() && options.opencv_partial_search) {
    const int largest = std::min({5, target.corners_x(), target.corners_y()});
    for (int k = largest; k >= options.min_partial_grid; --k) attempts.push_back({cv::Size(k, k), true});
  }
  return attempts;
}

Eigen::Vector2d ApplyHomography(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  return (h * p.homogeneous()).hnormalized();
}

// RMS of each corner against the homography of its 8 grid neighbours.
void LocalFit(const Target& target, const std::vector<int>& ids, const std::vector<Eigen::Vector2d>& q,
              DetectionQuality* quality) {
  const int nx = target.corners_x(), ny = target.corners_y();
  std::vector<int> index(target.num_corners(), -1);
  for (size_t i = 0; i < ids.size(); ++i) index[ids[i]] = static_cast<int>(i);
  double sum_sq = 0;
  int n = 0;
  for (int row = 1; row + 1 < ny; ++row) {
    for (int col = 1; col + 1 < nx; ++col) {
      const int centre = index[row * nx + col];
      if (centre < 0) continue;
      std::vector<cv::Point2d> src, dst;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) {
          const int k = index[(row + dr) * nx + col + dc];
          if ((!dr && !dc) || k < 0) continue;
          src.emplace_back(col + dc, row + dr);
          dst.emplace_back(q[k].x(), q[k].y());
        }
      }
      if (src.size() != 8) continue;
      const cv::Mat m = cv::findHomography(src, dst, 0);
      if (m.empty()) continue;
      Eigen::Matrix3d h;
      cv::cv2eigen(m, h);
      sum_sq += (ApplyHomography(h, Eigen::Vector2d(col, row)) - q[centre]).squaredNorm();
      ++n;
    }
  }
  quality->local_fit_count = n;
  quality->local_fit_rms_px = n ? std::sqrt(sum_sq / n) : std::numeric_limits<double>::quiet_NaN();
}

// Whether every corner, as the tags' homography predicts it, lies at least
// half a square inside the image.
bool WholeBoardInView(const Target& target, const Eigen::Matrix3d& image_from_face, const cv::Size& image_size) {
  const double s = target.square_size_mm();
  for (int id = 0; id < target.num_corners(); ++id) {
    const Eigen::Vector2d p = target.CornerInFace(id).head<2>();
    const Eigen::Vector2d q = ApplyHomography(image_from_face, p);
    const double half_square_px = 0.5 * (ApplyHomography(image_from_face, p + Eigen::Vector2d(s, 0)) - q).norm();
    if (!q.allFinite() || q.x() < half_square_px || q.y() < half_square_px ||
        q.x() > image_size.width - 1 - half_square_px || q.y() > image_size.height - 1 - half_square_px) {
      return false;
    }
  }
  return true;
}

// Each tag's corners against the homography of the detected corners alone.
// *bad_tag: the worst tag's ID if it is off by more than max_tag_fit_squares
// of a (local) square, else -1.
void TagFitAgainstCorners(const Target& target, Face face, const std::vector<TagDetection>& tags,
                          const std::vector<int>& ids, const std::vector<Eigen::Vector2d>& q, double max_fit_squares,
                          DetectionQuality* quality, int* bad_tag) {
  *bad_tag = -1;
  std::vector<cv::Point2d> src, dst;
  for (size_t i = 0; i < ids.size(); ++i) {
    const Eigen::Vector3d p = target.CornerInFace(ids[i]);
    src.emplace_back(p.x(), p.y());
    dst.emplace_back(q[i].x(), q[i].y());
  }
  const cv::Mat m = cv::findHomography(src, dst, 0);
  if (m.empty()) return;
  Eigen::Matrix3d h;
  cv::cv2eigen(m, h);
  const double s = target.square_size_mm();
  double sum_sq = 0, worst_ratio = 0;
  for (const TagDetection& t : tags) {
    const auto corners = TagCornersInFace(target, *target.FindTag(face, t.id));
    double tag_sq = 0;
    for (int k = 0; k < 4; ++k) tag_sq += (ApplyHomography(h, corners[k]) - t.q_px[k]).squaredNorm();
    sum_sq += tag_sq;
    const double tag_rms = std::sqrt(tag_sq / 4);
    const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    const double square_px = (ApplyHomography(h, centre + Eigen::Vector2d(s, 0)) - ApplyHomography(h, centre)).norm();
    quality->worst_tag_fit_px = std::max(quality->worst_tag_fit_px, tag_rms);
    if (tag_rms > max_fit_squares * square_px && tag_rms / square_px > worst_ratio) {
      worst_ratio = tag_rms / square_px;
      *bad_tag = t.id;
    }
  }
  quality->tag_fit_rms_px = tags.empty() ? 0 : std::sqrt(sum_sq / (4 * tags.size()));
}

// cv::estimateChessboardSharpness needs a complete rectangular grid: use the
// largest block of corners all found (OpenCV needs at least 3x3).
ChessboardSharpness SharpnessOfLargestBlock(const Target& target, const cv::Mat& grey, const std::vector<int>& ids,
                                            const std::vector<Eigen::Vector2d>& q) {
  const int nx = target.corners_x(), ny = target.corners_y();
  std::vector<int> index(target.num_corners(), -1);
  for (size_t i = 0; i < ids.size(); ++i) index[ids[i]] = static_cast<int>(i);
  // have[(r) * (nx + 1) + c]: found corners in rows < r, cols < c.
  std::vector<int> have((nx + 1) * (ny + 1), 0);
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c)
      have[(r + 1) * (nx + 1) + c + 1] =
          (index[r * nx + c] >= 0) + have[r * (nx + 1) + c + 1] + have[(r + 1) * (nx + 1) + c] - have[r * (nx + 1) + c];
  int best_area = 0, bc0 = 0, br0 = 0, bw = 0, bh = 0;
  for (int r0 = 0; r0 < ny; ++r0)
    for (int r1 = r0 + 3; r1 <= ny; ++r1)
      for (int c0 = 0; c0 < nx; ++c0)
        for (int c1 = c0 + 3; c1 <= nx; ++c1) {
          const int area = (r1 - r0) * (c1 - c0);
          const int count =
              have[r1 * (nx + 1) + c1] - have[r0 * (nx + 1) + c1] - have[r1 * (nx + 1) + c0] + have[r0 * (nx + 1) + c0];
          if (count == area && area > best_area) {
            best_area = area;
            bc0 = c0, br0 = r0, bw = c1 - c0, bh = r1 - r0;
          }
        }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (best_area == 0) return {nan, nan, nan};
  ChessboardGrid block;
  block.cols = bw;
  block.rows = bh;
  for (int r = br0; r < br0 + bh; ++r)
    for (int c = bc0; c < bc0 + bw; ++c) block.q_px.push_back(q[index[r * nx + c]]);
  return MeasureSharpness(grey, block);
}

}  // namespace

const char* CornerSourceName(CornerSource source) {
  switch (source) {
    case CornerSource::kNone:
      return "none";
    case CornerSource::kOpenCvGrid:
      return "opencv_grid";
    case CornerSource::kTagGuided:
      return "tag_guided";
  }
  return "unknown";
}

TargetDetector::TargetDetector(const Target& target, const DetectOptions& options)
    : target_(target), options_(options), tags_(target, options.tags) {
  options_.Check();
}

DetectResult TargetDetector::Detect(const cv::Mat& grey) const {
  if (grey.empty() || grey.type() != CV_8UC1) throw InputError("image", "expected a non-empty 8-bit grey image");
  DetectResult out;
  DetectionQuality& quality = out.quality;
  const int nx = target_.corners_x(), ny = target_.corners_y();

  // 1. Which face, from the tags (a double-sided target only).
  Face face = Face::kFront;
  std::vector<TagDetection> face_tags;
  Eigen::Matrix3d image_from_face = Eigen::Matrix3d::Identity();
  if (target_.double_sided()) {
    const std::vector<TagDetection> tags = tags_.Detect(grey, &quality.num_foreign_tags);
    std::vector<TagDetection> by_face[2];
    for (const TagDetection& t : tags) by_face[static_cast<int>(t.face)].push_back(t);
    if (!by_face[0].empty() && !by_face[1].empty()) {
      Reject(&out, RejectReason::kBothFaces,
             "tags of both faces seen (front " + IdList(by_face[0]) + ", back " + IdList(by_face[1]) +
                 "): which face is this?");
      return out;
    }
    if (tags.empty()) {
      // Tags are chiral: a mirrored image decodes none. Say so if that is why.
      cv::Mat flipped;
      cv::flip(grey, flipped, 1);
      if (!tags_.Detect(flipped).empty()) {
        Reject(&out, RejectReason::kMirrored, "the target's tags read only in the mirror image: a mirrored view");
      } else {
        Reject(&out, RejectReason::kNoTags, "no AprilTag of this target seen: face and orientation unknown");
      }
      return out;
    }
    face = tags.front().face;
    face_tags = by_face[static_cast<int>(face)];
    quality.num_tags = static_cast<int>(face_tags.size());
    for (const TagDetection& t : face_tags) quality.tag_ids.push_back(t.id);
    if (options_.expected_face && *options_.expected_face != face) {
      Reject(&out, RejectReason::kWrongFace,
             std::string("saw the ") + FaceName(face) + " face, expected the " + FaceName(*options_.expected_face));
      return out;
    }
    std::string problem;
    bool mirrored = false;
    if (!TagHomography(target_, face, face_tags, options_.max_tag_fit_squares, &image_from_face, &problem, &mirrored)) {
      Reject(&out, mirrored ? RejectReason::kMirrored : RejectReason::kAmbiguous, problem);
      return out;
    }
  }

  // 2. The corners and their ids: OpenCV's grid first; for a tagged target
  // whose grid is missing or wrong, corners grown out from the tags.
  std::vector<std::pair<int, Eigen::Vector2d>> found;  // (id, q_px)
  bool found_any_grid = false;
  std::string problem;  // from the largest grid that failed
  size_t largest_failed = 0;
  // OpenCV's whole-board search costs most when it fails (~1 s on a partial
  // view); with tags, the board's extent in the image is known beforehand.
  const bool try_opencv = !target_.double_sided() || options_.opencv_partial_search ||
                          (options_.opencv_whole_board && WholeBoardInView(target_, image_from_face, grey.size()));
  for (const auto& [size, partial] : GridAttempts(target_, options_)) {
    if (!try_opencv) break;
    ChessboardGrid grid;
    if (!FindChessboardGrid(grey, size, partial, options_.chessboard, &grid)) continue;
    found_any_grid = true;
    const GridIds ids = target_.double_sided()
                            ? GridIdsFromTags(target_, face, face_tags, image_from_face, grid, options_.id_gate_squares,
                                              options_.min_agreeing_fraction)
                            : GridIdsFromColours(target_, grey, grid);
    if (!ids.ok) {
      if (grid.q_px.size() > largest_failed) {
        largest_failed = grid.q_px.size();
        problem = ids.problem;
      }
      continue;
    }
    quality.source = CornerSource::kOpenCvGrid;
    quality.grid_cols = grid.cols;
    quality.grid_rows = grid.rows;
    quality.num_dropped = grid.num_dropped;
    for (int r = 0; r < grid.rows; ++r) {
      for (int c = 0; c < grid.cols; ++c) {
        if (!ids.keep[r * grid.cols + c] || !grid.usable[r * grid.cols + c]) continue;
        const Eigen::Vector2i id2 = ids.map(c, r);
        STEREORIG_CHECK(id2.x() >= 0 && id2.y() >= 0 && id2.x() < nx && id2.y() < ny);  // kept ones are on the board
        found.emplace_back(id2.y() * nx + id2.x(), grid.at(c, r));
      }
    }
    break;
  }
  if (found.empty() && target_.double_sided()) {
    const TagGuidedCorners grown =
        FindCornersFromTags(target_, face, face_tags, image_from_face, grey, options_.chessboard);
    for (size_t i = 0; i < grown.ids.size(); ++i) found.emplace_back(grown.ids[i], grown.q_px[i]);
    if (!found.empty()) {
      quality.source = CornerSource::kTagGuided;
    }
  }
  if (found.empty()) {
    if (!target_.double_sided() && found_any_grid) {
      Reject(&out, RejectReason::kGridMismatch, problem);
    } else if (!target_.double_sided()) {
      Reject(&out, RejectReason::kNoChessboard,
             "no complete " + std::to_string(nx) + "x" + std::to_string(ny) +
                 " chessboard found (a plain board must be wholly visible)");
    } else {
      Reject(&out, RejectReason::kNoChessboard, "no chessboard corners found next to the tags");
    }
    return out;
  }

  // 3. The detection, in id order.
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  FaceDetection det;
  det.face = face;
  for (size_t i = 0; i < found.size(); ++i) {
    STEREORIG_CHECK(i == 0 || found[i].first != found[i - 1].first);  // one corner per id
    det.corner_ids.push_back(found[i].first);
    det.q_px.push_back(found[i].second);
  }
  quality.num_corners = static_cast<int>(det.corner_ids.size());
  if (target_.double_sided() && quality.num_corners >= 4) {
    int worst_tag = -1;
    TagFitAgainstCorners(target_, face, face_tags, det.corner_ids, det.q_px, options_.max_tag_fit_squares, &quality,
                         &worst_tag);
    if (worst_tag >= 0) {
      std::ostringstream m;
      m << "tag " << worst_tag << " is " << quality.worst_tag_fit_px
        << " px from where the chessboard puts it: the target file or the print is wrong";
      Reject(&out, RejectReason::kAmbiguous, m.str());
      return out;
    }
  }
  quality.sharpness = SharpnessOfLargestBlock(target_, grey, det.corner_ids, det.q_px);
  LocalFit(target_, det.corner_ids, det.q_px, &quality);
  if (quality.num_corners < options_.min_corners) {
    Reject(
        &out, RejectReason::kTooFewCorners,
        "only " + std::to_string(quality.num_corners) + " corners (need " + std::to_string(options_.min_corners) + ")");
    return out;
  }
  det.quality = quality;
  out.faces.push_back(std::move(det));
  return out;
}

std::vector<FaceDetection> DetectTarget(const cv::Mat& grey, const Target& target, const DetectOptions& options,
                                        std::string* why_rejected) {
  const DetectResult r = TargetDetector(target, options).Detect(grey);
  if (why_rejected) *why_rejected = r.message;
  return r.faces;
}

}  // namespace stereorig
