#include "reconstruct/oblique_refine.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

void ObliqueOptions::Check() const {
  if (!(min_foreshortening > 0.2 && min_foreshortening < 1))
    throw InputError("grow_oblique_min_foreshortening", "must be in (0.2, 1)");
  if (!(psf_sigma_px > 0 && psf_sigma_px <= 3)) throw InputError("grow_oblique_psf_sigma_px", "must be in (0, 3] px");
  if (max_half_width_px < 1 || max_half_width_px > 30)
    throw InputError("grow_oblique_max_half_width_px", "must be in [1, 30] px");
}

namespace {

// Foreshortening levels: about sqrt(2) apart, so a pixel's s is within a
// factor 1.19 of its level's (a blur mismatch far below the blur itself).
constexpr double kLevels[] = {0.25, 0.35, 0.5, 0.7, 1.43, 2.0, 2.8, 4.0};

// Tiles of the lazily blurred views: a refinement reads ~3 rows and 30-100
// columns; a tile this size keeps OpenCV's per-call set-up small against
// the filtering itself.
constexpr int kTileRows = 8, kTileCols = 64;

}  // namespace

ObliqueViews::ObliqueViews(const cv::Mat& left, const cv::Mat& right, int row_begin, int row_end,
                           const ObliqueOptions& options)
    : left_(left), right_(right), identity_(cv::Mat::ones(1, 1, CV_32F)), options_(options) {
  if (!options.enabled) return;
  row_begin_ = std::max(0, row_begin), row_end_ = std::min(left.rows, row_end);
  if (row_end_ <= row_begin_) return;
  for (const double s : kLevels) {
    if (s > options.min_foreshortening && s < 1 / options.min_foreshortening) continue;
    Level level;
    level.foreshortening = s;
    level.blur_left = s < 1;
    // The sharper view takes on the other's blur: sigma_psf / s on the
    // surface seen from the left, i.e. sqrt(1/s^2 - 1) * sigma_psf more.
    const double k = s < 1 ? 1 / s : s;
    const double sigma = options.psf_sigma_px * std::sqrt(k * k - 1);
    const int radius = int(std::ceil(3 * sigma));
    level.kernel = cv::getGaussianKernel(2 * radius + 1, sigma, CV_32F);
    levels_.push_back(std::move(level));
  }
}

void ObliqueViews::EnsureBlurred(Level& level, int y0, int y1, int x0, int x1) const {
  const int cols = left_.cols;
  y0 = std::max(y0, row_begin_), y1 = std::min(y1, row_end_);
  x0 = std::max(x0, 0), x1 = std::min(x1, cols);
  if (y1 <= y0 || x1 <= x0) return;
  const cv::Mat& sharp = level.blur_left ? left_ : right_;
  cv::Mat& blurred = level.blur_left ? level.left : level.right;
  const int tiles_per_row = (cols + kTileCols - 1) / kTileCols;
  if (blurred.empty()) {
    // The other rows are never read at this level; copied so that the
    // views stay whole images for the refinement's row pointers.
    blurred = sharp.clone();
    (level.blur_left ? level.right : level.left) = level.blur_left ? right_ : left_;
    level.tile_done.assign(size_t((row_end_ - row_begin_ + kTileRows - 1) / kTileRows * tiles_per_row), false);
  }
  for (int ty = (y0 - row_begin_) / kTileRows; ty <= (y1 - 1 - row_begin_) / kTileRows; ++ty)
    for (int tx = x0 / kTileCols; tx <= (x1 - 1) / kTileCols; ++tx) {
      const size_t tile = size_t(ty * tiles_per_row + tx);
      if (level.tile_done[tile]) continue;
      level.tile_done[tile] = true;
      const int b = row_begin_ + ty * kTileRows;
      const cv::Rect rect = cv::Rect(tx * kTileCols, b, kTileCols, kTileRows) & cv::Rect(0, b, cols, row_end_ - b);
      // A view of the whole image: OpenCV reads the columns beyond the tile
      // from it (the image's own border only at its ends), so the tile is
      // what blurring whole rows gives.
      cv::Mat out = blurred(rect);
      cv::sepFilter2D(sharp(rect), out, CV_8U, level.kernel, identity_, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    }
}

bool ObliqueViews::Refine(int x, int y, double start_px, double slope_x, double slope_y, const RefineAcceptance& accept,
                          SubpixelResult* result, PixelStatus* status) const {
  const double s = 1 - slope_x;
  if (levels_.empty() || !(s > 0) || (s > options_.min_foreshortening && s < 1 / options_.min_foreshortening))
    return false;
  Level* best = nullptr;
  double best_distance = 0;  // |log(foreshortening / s)| of best, each level's computed once
  for (Level& level : levels_) {
    const double distance = std::abs(std::log(level.foreshortening / s));
    if (!best || distance < best_distance) best = &level, best_distance = distance;
  }
  RefineAcceptance a = accept;
  if (s < 1)
    a.subpixel.half_width_px = std::clamp(int(std::lround(accept.subpixel.half_width_px / s)),
                                          accept.subpixel.half_width_px, options_.max_half_width_px);
  // What the refinement and the acceptance read of the blurred view: rows
  // y +- half_height_px; in the left view the window's columns, in the
  // right one the columns the refinement checks it stays within (its
  // reach, subpixel_refine.cc) plus the distinctness test's shift. A margin
  // of kMarginPx either way in case they ever reach a little further.
  constexpr int kMarginPx = 8;
  const int rows = a.subpixel.half_height_px + 2;
  if (best->blur_left) {
    const int half = a.subpixel.half_width_px + kMarginPx;
    EnsureBlurred(*best, y - rows, y + rows + 1, x - half, x + half + 1);
  } else {
    const double reach = a.subpixel.half_width_px * (1 + std::abs(slope_x)) +
                         std::abs(slope_y) * a.subpixel.half_height_px + a.subpixel.max_shift_px + 4 +
                         DistinctnessShiftPx(slope_x, a) + kMarginPx;
    const double centre = x - start_px;
    EnsureBlurred(*best, y - rows, y + rows + 1, int(std::floor(centre - reach)), int(std::ceil(centre + reach)) + 1);
  }
  *status = RefineAndAccept(best->left, best->right, x, y, start_px, slope_x, slope_y, a, result);
  return true;
}

}  // namespace stereorig
