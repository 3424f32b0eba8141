// Whether a camera read from a rig file could be a real lens on its imager.
//
// Camera's constructor checks what makes the model computable (a known lens
// model, finite intrinsics, positive focal lengths and imager size). A rig
// file edited by hand, or written by a calibration that diverged, can pass
// that and still be nonsense that every later step trusts silently: fx
// typed as 1e12 (a field of view of nanodegrees: `reconstruct` then finds
// no point in that module, and says only "fill 0 %"), a k1 of -50 (the
// distortion folds back within a few dozen pixels of the centre, so most of
// the imager has no ray). These are refused when the file is read, naming
// the camera and what is wrong:
// - the principal point (cx, cy) lies on the imager (mrcal's pixel
//   convention: [-0.5, width - 0.5] x [-0.5, height - 0.5]);
// - the pixels are not far from square: fx / fy in [1/3, 3] (machine-vision
//   sensors are square to ~1 %, and binning one axis by 2, or one field of
//   an interlaced frame, gives 2; a factor above 3 is a typo, not a sensor);
// - the imager's width spans at least kMinFieldOfViewDeg of view;
// - the lens maps the imager one-to-one: along straight lines from the
//   principal point to the imager's corners and edge midpoints (8 lines,
//   kSamplesPerLine pixels each), every pixel unprojects to a ray that
//   projects back within kRoundTripTolerancePx, and the ray's angle to the
//   principal point's own ray grows strictly with the pixel's distance from
//   the principal point. A distortion that folds back fails one or the
//   other.
#pragma once

#include <string>

#include "calib/core/camera.h"

namespace stereorig {

inline constexpr double kMinFieldOfViewDeg = 0.1;
inline constexpr double kMaxPixelAspect = 3;  // fx / fy and fy / fx at most this
inline constexpr int kSamplesPerLine = 64;
inline constexpr double kRoundTripTolerancePx = 1e-3;

// Throws InputError starting with `where` (a file and key) on the first
// check that fails.
void CheckLensIsPlausible(const Camera& camera, const std::string& where);

}  // namespace stereorig
