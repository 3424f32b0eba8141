#include "targets/chessboard_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

void ChessboardGridOptions::Check() const {
  const std::string where = "chessboard detection";
  if (!(refine_window_fraction > 0 && refine_window_fraction <= 0.5)) {
    throw InputError(where, "refine_window_fraction must be in (0, 0.5]");
  }
  if (refine_min_half_px < 1 || refine_max_half_px < refine_min_half_px) {
    throw InputError(where, "need 1 <= refine_min_half_px <= refine_max_half_px");
  }
  if (!(refine_min_window_fraction >= 0 && refine_min_window_fraction <= refine_window_fraction)) {
    throw InputError(where, "refine_min_window_fraction must be in [0, refine_window_fraction]");
  }
  if (!(refine_max_shift_fraction > 0 && refine_max_shift_fraction <= 0.5)) {
    throw InputError(where, "refine_max_shift_fraction must be in (0, 0.5]");
  }
}

namespace {

// Distance from corner (c, r) to its nearest 4-neighbour in the grid, px.
double NearestNeighbourPx(const ChessboardGrid& g, int c, int r) {
  double best = std::numeric_limits<double>::infinity();
  const int dc[4] = {1, -1, 0, 0}, dr[4] = {0, 0, 1, -1};
  for (int k = 0; k < 4; ++k) {
    const int c2 = c + dc[k], r2 = r + dr[k];
    if (c2 < 0 || r2 < 0 || c2 >= g.cols || r2 >= g.rows) continue;
    best = std::min(best, (g.at(c2, r2) - g.at(c, r)).norm());
  }
  return best;
}

void Refine(const cv::Mat& grey, const ChessboardGridOptions& o, ChessboardGrid* g) {
  std::vector<Eigen::Vector2d> refined = g->q_px;
  for (int r = 0; r < g->rows; ++r) {
    for (int c = 0; c < g->cols; ++c) {
      const double spacing = NearestNeighbourPx(*g, c, r);
      if (!std::isfinite(spacing)) continue;
      const Eigen::Vector2d& q0 = g->at(c, r);
      const int half = RefineHalfWindow(o, spacing, q0, grey.size());
      if (half < 0) {
        g->usable[r * g->cols + c] = false;
        ++g->num_dropped;
        continue;
      }
      std::vector<cv::Point2f> p = {cv::Point2f(static_cast<float>(q0.x()), static_cast<float>(q0.y()))};
      cv::cornerSubPix(grey, p, cv::Size(half, half), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 1e-4));
      const Eigen::Vector2d q1(p[0].x, p[0].y);
      if (!q1.allFinite() ||
          (q1 - q0).norm() > std::min(o.refine_max_shift_fraction * spacing, static_cast<double>(half))) {
        g->usable[r * g->cols + c] = false;
        ++g->num_dropped;
        continue;
      }
      refined[r * g->cols + c] = q1;
    }
  }
  g->q_px = std::move(refined);
}

}  // namespace

int RefineHalfWindow(const ChessboardGridOptions& options, double spacing_px, const Eigen::Vector2d& q_px,
                     const cv::Size& image_size) {
  const double to_edge =
      std::min({q_px.x(), q_px.y(), image_size.width - 1 - q_px.x(), image_size.height - 1 - q_px.y()});
  const int half = std::min({static_cast<int>(std::floor(options.refine_window_fraction * spacing_px)),
                             options.refine_max_half_px, static_cast<int>(std::floor(to_edge)) - 2});
  if (half < options.refine_min_half_px || half < options.refine_min_window_fraction * spacing_px) return -1;
  return half;
}

bool FindChessboardGrid(const cv::Mat& grey, cv::Size size, bool partial, const ChessboardGridOptions& options,
                        ChessboardGrid* grid) {
  STEREORIG_CHECK(grey.type() == CV_8UC1 && grid != nullptr);
  options.Check();
  int flags = 0;
  if (options.exhaustive) flags |= cv::CALIB_CB_EXHAUSTIVE;
  if (options.upsample) flags |= cv::CALIB_CB_ACCURACY;
  if (partial) flags |= cv::CALIB_CB_LARGER;
  std::vector<cv::Point2f> corners;
  cv::Mat meta;
  // findChessboardCornersSB draws from OpenCV's thread-local RNG, so its
  // result depends on earlier calls; a fixed seed makes it repeatable.
  const cv::RNG saved = cv::theRNG();
  cv::theRNG() = cv::RNG(0x5eed);
  const bool found = cv::findChessboardCornersSB(grey, size, corners, flags, meta);
  cv::theRNG() = saved;
  if (!found) return false;
  // meta is (rows x cols); the corners follow it row-major.
  if (meta.empty() || static_cast<size_t>(meta.rows) * meta.cols != corners.size()) return false;
  grid->cols = meta.cols;
  grid->rows = meta.rows;
  grid->num_dropped = 0;
  grid->q_px.clear();
  for (const cv::Point2f& p : corners) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
    grid->q_px.emplace_back(p.x, p.y);
  }
  grid->usable.assign(grid->q_px.size(), true);
  if (options.refine) Refine(grey, options, grid);
  return true;
}

ChessboardSharpness MeasureSharpness(const cv::Mat& grey, const ChessboardGrid& grid) {
  std::vector<cv::Point2f> corners;
  for (const Eigen::Vector2d& q : grid.q_px) corners.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (grid.cols < 3 || grid.rows < 3) return {nan, nan, nan};  // OpenCV's minimum
  try {
    const cv::Scalar s = cv::estimateChessboardSharpness(grey, cv::Size(grid.cols, grid.rows), corners);
    return {s[0], s[1], s[2]};
  } catch (const cv::Exception&) {
    return {nan, nan, nan};  // a diagnostic only: never fail a detection for it
  }
}

}  // namespace stereorig
