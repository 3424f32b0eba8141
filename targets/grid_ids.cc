#include "targets/grid_ids.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

Eigen::Vector2d Apply(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  return (h * p.homogeneous()).hnormalized();
}

// d(pixel)/d(face mm) of homography `h` at `p`.
Eigen::Matrix2d Jacobian(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  const Eigen::Vector3d x = h * p.homogeneous();
  Eigen::Matrix2d j;
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k) j(i, k) = (h(i, k) * x.z() - x(i) * h(2, k)) / (x.z() * x.z());
  return j;
}

// Least squares, no robust step: callers pass inliers.
bool FitHomography(const std::vector<Eigen::Vector2d>& face_mm, const std::vector<Eigen::Vector2d>& q_px,
                   Eigen::Matrix3d* h) {
  STEREORIG_CHECK(face_mm.size() == q_px.size());
  if (face_mm.size() < 4) return false;
  std::vector<cv::Point2d> src, dst;
  for (size_t i = 0; i < face_mm.size(); ++i) {
    src.emplace_back(face_mm[i].x(), face_mm[i].y());
    dst.emplace_back(q_px[i].x(), q_px[i].y());
  }
  const cv::Mat m = cv::findHomography(src, dst, 0);
  if (m.empty()) return false;
  cv::cv2eigen(m, *h);
  return h->allFinite();
}

const std::vector<Eigen::Matrix2i>& Symmetries() {
  static const std::vector<Eigen::Matrix2i> all = [] {
    std::vector<Eigen::Matrix2i> v;
    Eigen::Matrix2i turn;
    turn << 0, -1, 1, 0;
    for (int flip = 0; flip < 2; ++flip) {
      Eigen::Matrix2i rot = Eigen::Matrix2i::Identity();
      for (int k = 0; k < 4; ++k) {
        Eigen::Matrix2i m = rot;
        if (flip) m.col(1) *= -1;
        v.push_back(m);
        rot = turn * rot;
      }
    }
    return v;
  }();
  return all;
}

void TagPoints(const Target& target, Face face, const std::vector<TagDetection>& tags,
               std::vector<Eigen::Vector2d>* face_mm, std::vector<Eigen::Vector2d>* q_px) {
  for (const TagDetection& t : tags) {
    const TagPlacement* placement = target.FindTag(face, t.id);
    STEREORIG_CHECK(placement != nullptr && t.face == face);
    const auto corners = TagCornersInFace(target, *placement);
    for (int k = 0; k < 4; ++k) {
      face_mm->push_back(corners[k]);
      q_px->push_back(t.q_px[k]);
    }
  }
}

struct Agreement {
  GridMap map;
  std::vector<bool> inlier;  // per grid corner
  int count = 0;
};

// The corners within `gate` squares of where `map` puts them, judged by
// each corner's face position `g` (squares) as a homography predicts it, and
// mapped onto one of the target's corners. OpenCV's grid may hold a row of
// the board's outer edge (where the outer squares meet the margin, not an
// inner corner): such corners map outside and are dropped here.
Agreement Agree(const Target& target, const ChessboardGrid& grid, const std::vector<Eigen::Vector2d>& g,
                const GridMap& map, double gate) {
  Agreement a;
  a.map = map;
  a.inlier.assign(g.size(), false);
  for (int r = 0; r < grid.rows; ++r) {
    for (int c = 0; c < grid.cols; ++c) {
      const int k = r * grid.cols + c;
      const Eigen::Vector2i id = map(c, r);
      if (id.x() < 0 || id.y() < 0 || id.x() >= target.corners_x() || id.y() >= target.corners_y()) continue;
      if ((g[k] - id.cast<double>()).norm() < gate) {
        a.inlier[k] = true;
        ++a.count;
      }
    }
  }
  return a;
}

// For symmetry `d`, the offset most of the corners in `use` vote for, and
// how many of those agree with it.
Agreement Vote(const Target& target, const ChessboardGrid& grid, const std::vector<Eigen::Vector2d>& g,
               const std::vector<bool>& use, const Eigen::Matrix2i& d, double gate) {
  std::map<std::pair<long, long>, int> votes;
  for (int r = 0; r < grid.rows; ++r) {
    for (int c = 0; c < grid.cols; ++c) {
      if (!use[r * grid.cols + c]) continue;
      const Eigen::Vector2d rest = g[r * grid.cols + c] - (d * Eigen::Vector2i(c, r)).cast<double>();
      if (rest.allFinite()) ++votes[{std::lround(rest.x()), std::lround(rest.y())}];
    }
  }
  GridMap map;
  map.d = d;
  if (!votes.empty()) {
    const auto best =
        std::max_element(votes.begin(), votes.end(), [](const auto& x, const auto& y) { return x.second < y.second; });
    map.offset = Eigen::Vector2i(static_cast<int>(best->first.first), static_cast<int>(best->first.second));
  }
  Agreement a = Agree(target, grid, g, map, gate);
  for (size_t k = 0; k < use.size(); ++k) {
    if (a.inlier[k] && !use[k]) {
      a.inlier[k] = false;
      --a.count;
    }
  }
  return a;
}

std::vector<Eigen::Vector2d> FacePositions(const ChessboardGrid& grid, const Eigen::Matrix3d& image_from_face,
                                           double square_mm) {
  const Eigen::Matrix3d face_from_image = image_from_face.inverse();
  std::vector<Eigen::Vector2d> g;
  for (const Eigen::Vector2d& q : grid.q_px) g.push_back(Apply(face_from_image, q) / square_mm);
  return g;
}

double SampleBilinear(const cv::Mat& grey, const Eigen::Vector2d& q) {
  const double x = std::clamp(q.x(), 0.0, grey.cols - 1.001), y = std::clamp(q.y(), 0.0, grey.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xx, int yy) { return static_cast<double>(grey.at<uint8_t>(yy, xx)); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

}  // namespace

bool TagHomography(const Target& target, Face face, const std::vector<TagDetection>& tags, double max_fit_squares,
                   Eigen::Matrix3d* image_from_face, std::string* problem, bool* mirrored) {
  *mirrored = false;
  std::vector<Eigen::Vector2d> src, dst;
  TagPoints(target, face, tags, &src, &dst);
  if (!FitHomography(src, dst, image_from_face)) {
    *problem = "the tags' corners fit no homography";
    return false;
  }
  // Seen from the front, the face's x and y axes keep the image's handedness
  // (both frames have z pointing away from the viewer).
  const Eigen::Vector2d centre = std::accumulate(src.begin(), src.end(), Eigen::Vector2d(0, 0)) / src.size();
  const Eigen::Matrix2d j = Jacobian(*image_from_face, centre);
  if (j.determinant() <= 0) {
    *mirrored = true;
    *problem = "the tags appear mirrored";
    return false;
  }
  const double square_px = std::sqrt(j.determinant()) * target.square_size_mm();
  double sum_sq = 0;
  for (size_t i = 0; i < src.size(); ++i) sum_sq += (Apply(*image_from_face, src[i]) - dst[i]).squaredNorm();
  const double rms_px = std::sqrt(sum_sq / src.size());
  if (rms_px > max_fit_squares * square_px) {
    std::ostringstream m;
    m << "the tags disagree on the board's position (" << rms_px << " px RMS from one homography)";
    *problem = m.str();
    return false;
  }
  return true;
}

GridIds GridIdsFromTags(const Target& target, Face face, const std::vector<TagDetection>& tags,
                        const Eigen::Matrix3d& image_from_face, const ChessboardGrid& grid, double gate_squares,
                        double min_agreeing_fraction) {
  GridIds out;
  const double s = target.square_size_mm();
  const int n = grid.cols * grid.rows;
  std::vector<Eigen::Vector2d> tag_mm, tag_px;
  TagPoints(target, face, tags, &tag_mm, &tag_px);

  // The tags' homography is good near the tags and may be poor far from
  // them (four tags along one margin are nearly collinear). So the symmetry
  // and offset are voted by the corners near a tag only: those within 2.5
  // squares of the nearest one's distance.
  std::vector<Eigen::Vector2d> g = FacePositions(grid, image_from_face, s);
  std::vector<double> tag_distance(n, std::numeric_limits<double>::infinity());
  for (int k = 0; k < n; ++k) {
    for (const TagDetection& t : tags) {
      const TagPlacement* placement = target.FindTag(face, t.id);
      const Eigen::Vector2d centre(placement->center_x_mm / s, placement->center_y_mm / s);
      tag_distance[k] = std::min(tag_distance[k], (g[k] - centre).norm());
    }
  }
  const double nearest = *std::min_element(tag_distance.begin(), tag_distance.end());
  std::vector<bool> near(n);
  int num_near = 0;
  for (int k = 0; k < n; ++k) num_near += near[k] = tag_distance[k] <= nearest + 2.5;
  Agreement best, second;
  for (const Eigen::Matrix2i& d : Symmetries()) {
    Agreement a = Vote(target, grid, g, near, d, gate_squares);
    if (a.count > best.count) {
      second = best;
      best = a;
    } else if (a.count > second.count) {
      second = a;
    }
  }
  if (best.count < 3 || second.count * 2 >= best.count || best.count < min_agreeing_fraction * num_near) {
    out.problem = "the corners next to the tags fit no single orientation (" + std::to_string(best.count) + " vs " +
                  std::to_string(second.count) + " of " + std::to_string(num_near) + " corners)";
    return out;
  }
  // Grow: refit the homography to the tags and the agreeing corners, so that
  // it reaches across the board (and follows mild lens distortion), and
  // take in the corners that now agree with the same symmetry and offset.
  Eigen::Matrix3d h = image_from_face;
  for (int iteration = 0; iteration < 5; ++iteration) {
    std::vector<Eigen::Vector2d> src = tag_mm, dst = tag_px;
    for (int r = 0; r < grid.rows; ++r) {
      for (int c = 0; c < grid.cols; ++c) {
        if (!best.inlier[r * grid.cols + c]) continue;
        src.push_back(best.map(c, r).cast<double>() * s);
        dst.push_back(grid.at(c, r));
      }
    }
    if (!FitHomography(src, dst, &h)) break;
    const int before = best.count;
    best = Agree(target, grid, FacePositions(grid, h, s), best.map, gate_squares);
    if (best.count == before) break;
  }
  if (best.count < min_agreeing_fraction * n) {
    out.problem =
        "only " + std::to_string(best.count) + " of " + std::to_string(n) + " corners sit where the tags put them";
    return out;
  }
  double sum_sq = 0;
  for (size_t i = 0; i < tag_mm.size(); ++i) sum_sq += (Apply(h, tag_mm[i]) - tag_px[i]).squaredNorm();
  out.ok = true;
  out.map = best.map;
  out.keep = best.inlier;
  out.tag_fit_rms_px = std::sqrt(sum_sq / tag_mm.size());
  return out;
}

GridIds GridIdsFromColours(const Target& target, const cv::Mat& grey, const ChessboardGrid& grid) {
  GridIds out;
  const int nx = target.corners_x(), ny = target.corners_y();
  const double s = target.square_size_mm();
  if (!((grid.cols == nx && grid.rows == ny) || (grid.cols == ny && grid.rows == nx))) {
    out.problem = "found a " + std::to_string(grid.cols) + "x" + std::to_string(grid.rows) +
                  " corner grid, the target has " + std::to_string(nx) + "x" + std::to_string(ny);
    return out;
  }
  // The image's steps along OpenCV's grid axes.
  Eigen::Matrix2d image_from_grid;
  image_from_grid.col(0) = (grid.at(grid.cols - 1, 0) - grid.at(0, 0)) / (grid.cols - 1);
  image_from_grid.col(1) = (grid.at(0, grid.rows - 1) - grid.at(0, 0)) / (grid.rows - 1);
  struct Candidate {
    GridMap map;
    std::vector<bool> black;  // expected colour of each inner square, OpenCV order
    double contrast_dn = 0;   // mean(expected white) - mean(expected black), sampled
    double rightwards = 0;    // image u-component of the face's unit x axis
  };
  std::vector<Candidate> candidates;
  for (const Eigen::Matrix2i& d : Symmetries()) {
    Candidate cand;
    cand.map.d = d;
    const Eigen::Vector2i a = d * Eigen::Vector2i(0, 0), b = d * Eigen::Vector2i(grid.cols - 1, grid.rows - 1);
    cand.map.offset = -a.cwiseMin(b);
    if (a.cwiseMax(b) + cand.map.offset != Eigen::Vector2i(nx - 1, ny - 1)) continue;
    const Eigen::Matrix2d image_from_face_grid = image_from_grid * d.cast<double>().inverse();
    if (image_from_face_grid.determinant() <= 0) continue;  // would be a view from behind
    cand.rightwards = image_from_face_grid.col(0).normalized().x();
    double sum[2] = {0, 0};
    int count[2] = {0, 0};
    for (int r = 0; r + 1 < grid.rows; ++r) {
      for (int c = 0; c + 1 < grid.cols; ++c) {
        const Eigen::Vector2d centre_mm = 0.5 * (cand.map(c, r) + cand.map(c + 1, r + 1)).cast<double>() * s;
        const bool black = target.IsBlack(Face::kFront, centre_mm.x(), centre_mm.y());
        const Eigen::Vector2d q =
            0.25 * (grid.at(c, r) + grid.at(c + 1, r) + grid.at(c, r + 1) + grid.at(c + 1, r + 1));
        sum[black] += SampleBilinear(grey, q);
        ++count[black];
        cand.black.push_back(black);
      }
    }
    cand.contrast_dn = sum[0] / std::max(1, count[0]) - sum[1] / std::max(1, count[1]);
    candidates.push_back(cand);
  }
  if (candidates.empty()) {
    out.problem = "the corner grid fits the target in no orientation";
    return out;
  }
  // Colour twins sample the same squares with the same expectations, so
  // their contrasts are equal; the image's right direction breaks the tie.
  const Candidate* best_colour =
      &*std::max_element(candidates.begin(), candidates.end(),
                         [](const Candidate& x, const Candidate& y) { return x.contrast_dn < y.contrast_dn; });
  const Candidate* chosen = best_colour;
  for (const Candidate& cand : candidates) {
    if (cand.black == best_colour->black && cand.rightwards > chosen->rightwards) chosen = &cand;
  }
  if (chosen->contrast_dn <= 0) {
    out.problem = "cannot tell the black squares from the white ones";
    return out;
  }
  out.ok = true;
  out.map = chosen->map;
  out.keep.assign(grid.q_px.size(), true);
  return out;
}

}  // namespace stereorig
