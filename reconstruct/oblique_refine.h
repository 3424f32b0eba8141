// Refining matches on surfaces that one camera sees much more obliquely than
// the other (the limbs of spheres and cylinders, a bar's flanks).
//
// There the disparity slope dd/dx is far from 0: a left window of width w
// covers s * w right pixels, s = 1 - dd/dx. The plain refinement
// (subpixel_refine.h) warps the right window by s but compares the two views
// at their native resolutions, and they differ: where s < 1 the right camera
// has blurred the laser lines over 1/s times as many surface mm as the left
// (its PSF and pixel are 1/s times wider on the surface), and its 9 px window
// spans only 9 s right pixels, less than a grid period; where s > 1 the
// same holds with the views swapped, and the Lanczos taps sample the right
// row at a stride s > 1, aliasing it. Measured on the simulator's sphere
// (`stereorig score --diagnose`): of the target pixels with s < 0.5, 0-45 %
// are filled, with s > 1.5 14-83 %, against 90-98 % elsewhere, and the
// refinement fails there even when started from the truth disparity.
//
// The fix matches the views at a common resolution: the sharper one is
// low-passed along the rows by a Gaussian of sigma_psf * sqrt(k^2 - 1)
// (k = 1/s for the left view, s for the right one), and the left window is
// widened to max(w, w / s) so that the right one spans about a grid period.
// The blurred views are made once per capture at a few levels of s
// (ObliqueViews); a pixel uses the level nearest to its own s. It is a
// fallback for pixels the plain refinement has rejected, inside growing
// (region_grow.h), judged by the same acceptance tests (disparity_state.h).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "reconstruct/disparity_state.h"

namespace stereorig {

struct ObliqueOptions {
  bool enabled = true;  // default true
  // Below this foreshortening s or above 1/this, the fallback is tried; default 0.7 (so s < 0.7 or s > 1.43).
  double min_foreshortening = 0.7;
  double psf_sigma_px = 0.7;   // the cameras' blur (PSF and pixel), 1 sigma, px; default 0.7 (simulator: PSF 0.6 + box)
  int max_half_width_px = 12;  // the widened left window's half width, at most; default 12 px
  void Check() const;          // throws InputError naming the bad field
};

// The pair low-passed at a few foreshortening levels, for one capture.
// A level's views are blurred on first use, tile by tile as pixels ask for
// them (the filter runs along the rows and reads the whole image around a
// tile, so a pixel's result does not depend on which tiles are blurred):
// growing asks for a few levels at a few thousand scattered pixels, and
// blurring everything up front cost more (~60 M instructions per module on
// the demo cup) than the refinements that use it. Not thread-safe: Refine
// fills that cache.
class ObliqueViews {
 public:
  // left, right: CV_8UC1 rectified, shared, not copied (they must stay
  // unchanged while this is used). Only rows [row_begin, row_end) are filtered
  // (the matched region plus the refinement window's reach).
  ObliqueViews(const cv::Mat& left, const cv::Mat& right, int row_begin, int row_end, const ObliqueOptions& options);

  // The refinement of left pixel (x, y) from start_px with slopes (gx, gy)
  // at the level nearest s = 1 - gx, accepted or not by `accept` (status
  // kPoint if accepted). False if s is within the plain refinement's range
  // (nothing tried).
  bool Refine(int x, int y, double start_px, double slope_x, double slope_y, const RefineAcceptance& accept,
              SubpixelResult* result, PixelStatus* status) const;

 private:
  struct Level {
    double foreshortening;        // s this level is made for
    bool blur_left;               // which view is the sharper one, low-passed: the left where s < 1
    cv::Mat kernel;               // the Gaussian along the rows, CV_32F column
    cv::Mat left, right;          // the sharper view's copy is blurred tile by tile (empty until first used)
    std::vector<bool> tile_done;  // per tile (kTileRows x kTileCols from (0, row_begin_), row-major): blurred yet
  };
  // Blurs the tiles of `level`'s sharper view that meet rows [y0, y1) x
  // columns [x0, x1) and are not yet.
  void EnsureBlurred(Level& level, int y0, int y1, int x0, int x1) const;

  cv::Mat left_, right_;
  cv::Mat identity_;  // the filter across the rows: none (1x1 CV_32F, 1)
  int row_begin_ = 0, row_end_ = 0;
  ObliqueOptions options_;
  mutable std::vector<Level> levels_;
};

}  // namespace stereorig
