#include "targets/tag_guided_corners.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"
#include "targets/chessboard_grid.h"

namespace stereorig {

namespace {

Eigen::Vector2d Apply(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  return (h * p.homogeneous()).hnormalized();
}

double SampleBilinear(const cv::Mat& grey, const Eigen::Vector2d& q) {
  const double x = std::clamp(q.x(), 0.0, grey.cols - 1.001), y = std::clamp(q.y(), 0.0, grey.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xx, int yy) { return static_cast<double>(grey.at<uint8_t>(yy, xx)); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

enum class State { kUntried, kAccepted, kRejected };

}  // namespace

TagGuidedCorners FindCornersFromTags(const Target& target, Face face, const std::vector<TagDetection>& tags,
                                     const Eigen::Matrix3d& image_from_face, const cv::Mat& grey,
                                     const ChessboardGridOptions& refine) {
  const int nx = target.corners_x(), ny = target.corners_y(), n = target.num_corners();
  const double s = target.square_size_mm();
  std::vector<Eigen::Vector2d> tag_mm, tag_px;
  for (const TagDetection& t : tags) {
    const auto corners = TagCornersInFace(target, *target.FindTag(face, t.id));
    for (int k = 0; k < 4; ++k) {
      tag_mm.push_back(corners[k]);
      tag_px.push_back(t.q_px[k]);
    }
  }
  auto face_mm = [&](int id) { return Eigen::Vector2d(target.CornerInFace(id).head<2>()); };

  // The first ring: the corners nearest the tags (within 1.5 squares of the
  // nearest one's distance), where the tags' homography is best.
  std::vector<double> to_tag(n, std::numeric_limits<double>::infinity());
  for (int id = 0; id < n; ++id) {
    for (const TagDetection& t : tags) {
      const TagPlacement* p = target.FindTag(face, t.id);
      to_tag[id] = std::min(to_tag[id], (face_mm(id) - Eigen::Vector2d(p->center_x_mm, p->center_y_mm)).norm() / s);
    }
  }
  const double nearest = *std::min_element(to_tag.begin(), to_tag.end());
  std::vector<State> state(n, State::kUntried);
  std::vector<Eigen::Vector2d> q(n);
  std::vector<bool> candidate(n);
  for (int id = 0; id < n; ++id) candidate[id] = to_tag[id] <= nearest + 1.5;

  Eigen::Matrix3d h = image_from_face;
  for (int round = 0; round < nx + ny; ++round) {
    int added = 0;
    for (int id = 0; id < n; ++id) {
      if (!candidate[id] || state[id] != State::kUntried) continue;
      state[id] = State::kRejected;  // unless it passes every test below
      const Eigen::Vector2d p = face_mm(id);
      const Eigen::Vector2d q0 = Apply(h, p);
      const double spacing = std::min((Apply(h, p + Eigen::Vector2d(s, 0)) - q0).norm(),
                                      (Apply(h, p + Eigen::Vector2d(0, s)) - q0).norm());
      if (!q0.allFinite() || spacing < 4.0 * refine.refine_min_half_px) continue;  // too small to refine
      const int half = RefineHalfWindow(refine, spacing, q0, grey.size());
      if (half < 0) continue;  // out of view
      std::vector<cv::Point2f> pt = {cv::Point2f(static_cast<float>(q0.x()), static_cast<float>(q0.y()))};
      cv::cornerSubPix(grey, pt, cv::Size(half, half), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 1e-4));
      const Eigen::Vector2d q1(pt[0].x, pt[0].y);
      if (!q1.allFinite() ||
          (q1 - q0).norm() > std::min(refine.refine_max_shift_fraction * spacing, static_cast<double>(half)))
        continue;
      // The saddle: the four squares around the corner, sampled 0.3 of a
      // square along each diagonal, have the target's colours.
      double black_max = -1, white_min = 1e9, black_sum = 0, white_sum = 0;
      for (int sx : {-1, 1}) {
        for (int sy : {-1, 1}) {
          const Eigen::Vector2d pq = p + 0.3 * s * Eigen::Vector2d(sx, sy);
          const double v = SampleBilinear(grey, q1 + Apply(h, pq) - q0);
          if (target.IsBlack(face, pq.x(), pq.y())) {
            black_max = std::max(black_max, v);
            black_sum += v;
          } else {
            white_min = std::min(white_min, v);
            white_sum += v;
          }
        }
      }
      const double contrast = 0.5 * (white_sum - black_sum);
      if (white_min - black_max < std::max(10.0, 0.3 * contrast)) continue;
      state[id] = State::kAccepted;
      q[id] = q1;
      ++added;
    }
    if (!added) break;
    // Refit through the tags and every corner kept, and offer the kept
    // corners' neighbours next.
    std::vector<cv::Point2d> src, dst;
    for (size_t i = 0; i < tag_mm.size(); ++i) {
      src.emplace_back(tag_mm[i].x(), tag_mm[i].y());
      dst.emplace_back(tag_px[i].x(), tag_px[i].y());
    }
    for (int id = 0; id < n; ++id) {
      if (state[id] != State::kAccepted) continue;
      src.emplace_back(face_mm(id).x(), face_mm(id).y());
      dst.emplace_back(q[id].x(), q[id].y());
      const int col = id % nx, row = id / nx;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc)
          if (col + dc >= 0 && col + dc < nx && row + dr >= 0 && row + dr < ny)
            candidate[(row + dr) * nx + col + dc] = true;
    }
    const cv::Mat m = cv::findHomography(src, dst, 0);
    if (!m.empty()) cv::cv2eigen(m, h);
  }

  TagGuidedCorners out;
  for (int id = 0; id < n; ++id) {
    if (state[id] != State::kAccepted) continue;
    out.ids.push_back(id);
    out.q_px.push_back(q[id]);
  }
  double sum_sq = 0;
  for (size_t i = 0; i < tag_mm.size(); ++i) sum_sq += (Apply(h, tag_mm[i]) - tag_px[i]).squaredNorm();
  out.tag_fit_rms_px = tag_mm.empty() ? 0 : std::sqrt(sum_sq / tag_mm.size());
  return out;
}

}  // namespace stereorig
