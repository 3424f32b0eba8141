// Dropping points that no laser line supports.
//
// The active matcher measures the projected grid: a match is evidence of
// the surface only where the grid's lines are in its window. Elsewhere,
// in an ambient-lit part of the object beside the grid's envelope, the
// window holds smooth shading and, near the object's outline, the step
// from the object to the background. That step is no correspondence (the
// two cameras see the outline at different points of the surface), yet a
// window holding it correlates well: growing's windows shifted towards a
// grown neighbour (shifted_window.h) carried the limb's disparity up to ~8
// px past the grid's envelope along a ball's outline, 1-1.5 mm off the
// surface (a fresh realization's ball bar, seed 6, module 0: 141 such
// points, std 0.105 mm; docs/reconstruct-log.md, session 25).
//
// A laser line is a ridge: along a row (or a column) its peak stands at
// least `min_prominence_dn` above the lowest grey within `reach_px` on both
// sides (reach: half the grid's period, so that the trough between two
// lines is within it). An outline's step rises on one side only, smooth
// shading by less, and sensor noise by a few DN: none of them is a ridge.
// A point is supported when its (2 radius + 1)^2 window holds at least
// `min_ridge_px` ridge pixels; inside the grid's envelope every pixel lies
// within half a period of a line in both directions, so a window wider
// than that always holds one.
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"

namespace stereorig {

struct GridLineOptions {
  bool enabled = true;           // default true; off for passive captures (no grid)
  double min_prominence_dn = 8;  // a ridge's height above the lowest grey within reach on each side; default 8 DN
  int radius_px = 5;             // the window's half size; default 5 px (half the default grid's period + 1)
  int min_ridge_px = 3;          // ridge pixels the window must hold; default 3
  void Check() const;            // throws InputError naming the bad key
};

// CV_8UC1 of grey's size: 1 where the pixel is a ridge along its row or its
// column (the test above, reach_px >= 1 on each side; pixels nearer than
// reach_px to the image's edge in that direction are not tested along it),
// else 0. grey: CV_8UC1, may be a view.
cv::Mat GridRidges(const cv::Mat& grey, int reach_px, double min_prominence_dn);

// Sets every valid pixel of `roi` whose window holds fewer than
// o.min_ridge_px ridge pixels (GridRidges of `left`, read around roi too) to
// +inf, confidence 0, status PixelStatus::kNoGridLine. left: the rectified
// left image (CV_8UC1) the disparity map belongs to. Returns the pixels
// dropped; nothing if !o.enabled.
int DropWithoutGridLine(const cv::Mat& left, const GridLineOptions& o, int reach_px, const cv::Rect& roi,
                        DisparityState* state);

}  // namespace stereorig
