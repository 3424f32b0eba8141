// Whether a camera read from a rig file could be a real lens on its imager.
//
// Camera's constructor checks what makes the model computable (a known lens
// model, finite intrinsics, positive focal lengths and imager size). A rig
// file edited by hand, or written by a calibration that diverged, can pass
// that and still be nonsense that every later step trusts silently: fx
// typed as 1e12 (a field of view of nanodegrees: `reconstruct` then finds
// no point in that module, and says only "fill 0 %"), a k1 of -50 (the
// distortion folds back within a few dozen pixels of the centre, so most of
// the imager has no ray), cx typed in the wrong units. These are refused
// when the file is read, naming the camera and what is wrong:
// - the imager lies within the lens's image circle: no imager pixel is more
//   than kMaxImageCircleRadiusPx from the principal point (cx, cy), the
//   circle's centre;
// - the pixels are not far from square: fx / fy in [1/3, 3] (machine-vision
//   sensors are square to ~1 %, and binning one axis by 2, or one field of
//   an interlaced frame, gives 2; a factor above 3 is a typo, not a sensor);
// - the lens maps the imager one-to-one: along straight lines from the
//   principal point to the imager's corners and to the point of each edge
//   nearest the principal point (its midpoint, seen from a principal point
//   on the imager), every pixel unprojects to a ray that projects back
//   within kRoundTripTolerancePx, and the ray's angle to the principal
//   point's own ray grows strictly with the pixel's distance from the
//   principal point. A distortion that folds back fails one or the other.
//   Each line is sampled at kSamplesPerLine pixels over its part on the
//   imager, and, if the principal point is off the imager, over the stretch
//   before it at the same spacing (at most kSamplesPerLine pixels): a real
//   lens maps that stretch one-to-one too (it lies in the image circle,
//   between the axis and the imager), so a model that folds there is no
//   lens; and a principal point in the wrong place often puts the stretch
//   where a distortion fitted over the imager folds (a cx in um, below);
// - the imager's pixel nearest the principal point sees less than
//   kMaxOffAxisDeg off the optical axis;
// - the imager's width spans at least kMinFieldOfViewDeg of view (between
//   its left and right edges, at the row nearest the principal point).
//
// The principal point may lie off the imager: a sensor read out in a window
// (a region of interest: 640 x 480 at a corner of a 1920 x 1200 sensor, or
// a 1920 x 200 strip of it) keeps the lens's principal point, in window
// coordinates, where it was on the whole sensor, so outside the window. What
// cannot be told from the file: a window's principal point given in
// whole-sensor coordinates, or a pinhole's cx in um that still lands within
// the limits (some larger sensor's window would have it).
#pragma once

#include <string>

#include "calib/core/camera.h"

namespace stereorig {

inline constexpr double kMinFieldOfViewDeg = 0.1;
inline constexpr double kMaxPixelAspect = 3;  // fx / fy and fy / fx at most this
inline constexpr int kSamplesPerLine = 64;
inline constexpr double kRoundTripTolerancePx = 1e-3;

// The image circle is centred on the optical axis, (cx, cy), and holds every
// pixel of the imager, a window included (the lens must cover the sensor the
// window is read from; a shifted lens moves the circle, not the pixels out
// of it). The largest radius in pixels a camera can reach: a 4x5-inch view
// camera's wide lens, made to cover ~240 mm so that it can be shifted,
// before a medium-format back's 3.76 um pixels: 120 mm / 3.76 um = 32000
// px; 2^16 leaves margin above it. A principal point further out is a typo
// or the wrong units (nm, or mm taken for um: x 1000), and a lens model
// evaluated that far out is meaningless. (A cx in um, x 1.1 to 10, is
// within this bound; the one-to-one walk refuses it when the
// distortion, fitted over the imager, folds in the stretch before it.)
inline constexpr double kMaxImageCircleRadiusPx = 65536;

// A ray at 90 deg from the optical axis passes beside the lens. A
// rectilinear lens (pinhole and OpenCV models) cannot image it (it would
// land infinitely far from (cx, cy)); a fisheye images it, but in a rig
// looking at an object only at the rim of an image circle that also holds
// the axis. So even a window at the corner of the widest lenses' sensors
// (the widest rectilinear lenses see ~67 deg off axis at the corner, 135 deg
// across the diagonal; a 180 deg diagonal fisheye 90 deg) has its nearest
// pixel within 90 deg of the axis. A window wholly outside that cone, cut
// from the rim of a fisheye of over 180 deg, is refused: a known limit.
inline constexpr double kMaxOffAxisDeg = 90;

// Throws InputError starting with `where` (a file and key) on the first
// check that fails.
void CheckLensIsPlausible(const Camera& camera, const std::string& where);

}  // namespace stereorig
