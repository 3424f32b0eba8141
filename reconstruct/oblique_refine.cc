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

// Rows [b, e) of `image` low-passed along the rows by a Gaussian of sigma px
// (the other rows copied: they are never read at this level).
cv::Mat BlurRows(const cv::Mat& image, int b, int e, double sigma) {
  cv::Mat out = image.clone();
  const int radius = int(std::ceil(3 * sigma));
  const cv::Mat kx = cv::getGaussianKernel(2 * radius + 1, sigma, CV_32F);
  const cv::Mat ky = (cv::Mat_<float>(1, 1) << 1.f);
  cv::Mat rows = out.rowRange(b, e);
  cv::sepFilter2D(image.rowRange(b, e), rows, CV_8U, kx, ky, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  return out;
}

}  // namespace

ObliqueViews::ObliqueViews(const cv::Mat& left, const cv::Mat& right, int row_begin, int row_end,
                           const ObliqueOptions& options)
    : options_(options) {
  if (!options.enabled) return;
  const int b = std::max(0, row_begin), e = std::min(left.rows, row_end);
  if (e <= b) return;
  for (const double s : kLevels) {
    if (s > options.min_foreshortening && s < 1 / options.min_foreshortening) continue;
    Level level;
    level.foreshortening = s;
    // The sharper view takes on the other's blur: sigma_psf / s on the
    // surface seen from the left, i.e. sqrt(1/s^2 - 1) * sigma_psf more.
    const double k = s < 1 ? 1 / s : s;
    const double sigma = options.psf_sigma_px * std::sqrt(k * k - 1);
    level.left = s < 1 ? BlurRows(left, b, e, sigma) : left;
    level.right = s < 1 ? right : BlurRows(right, b, e, sigma);
    levels_.push_back(std::move(level));
  }
}

bool ObliqueViews::Refine(int x, int y, double start_px, double slope_x, double slope_y, const RefineAcceptance& accept,
                          SubpixelResult* result, PixelStatus* status) const {
  const double s = 1 - slope_x;
  if (levels_.empty() || !(s > 0) || (s > options_.min_foreshortening && s < 1 / options_.min_foreshortening))
    return false;
  const Level* best = nullptr;
  for (const Level& level : levels_)
    if (!best || std::abs(std::log(level.foreshortening / s)) < std::abs(std::log(best->foreshortening / s)))
      best = &level;
  RefineAcceptance a = accept;
  if (s < 1)
    a.subpixel.half_width_px = std::clamp(int(std::lround(accept.subpixel.half_width_px / s)),
                                          accept.subpixel.half_width_px, options_.max_half_width_px);
  *result = RefineDisparity(best->left, best->right, x, y, start_px, slope_x, slope_y, a.subpixel);
  *status = Accept(best->left, best->right, x, y, slope_x, slope_y, *result, a);
  return true;
}

}  // namespace stereorig
