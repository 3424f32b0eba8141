// The pinhole stage 1 starts from (calib/intrinsics.h): a focal length and a
// principal point, before any distortion, from which each view's board pose
// is seeded (PnP) and mrcal's solve begins.
//
// A sensor read out in a window (a region of interest) keeps the lens's
// principal point where it was on the sensor, so in window coordinates it is
// off-centre, and off the image for a window at a sensor's corner. A seed
// that puts it at the window's centre is then hundreds of pixels wrong, and
// the focal length estimated under that assumption (OpenCV's
// initCameraMatrix2D) with it: 126 px for a 1025 px lens behind a 320 x 240
// window at the corner of a 1920 x 1200 sensor, whose board poses then
// looked fronto-parallel and stage 1 refused them ("tilt the board").
// So the seed is chosen among candidates, by how well each explains every
// view on its own: the RMS reprojection error after each view's board pose
// is solved for alone (PnP, IPPE) through the candidate's pinhole. The
// candidates:
// - Zhang's closed form ("A flexible new technique for camera calibration",
//   2000, section 3.1) with square pixels and no skew: each view's
//   homography h1, h2 (board plane -> pixels, pixels centred on the image
//   and scaled by its larger side) gives h1' B h2 = 0 and
//   h1' B h1 = h2' B h2 for B ~ K^-T K^-1, linear in (B11 = B22, B13, B23,
//   B33); then c = -(B13, B23) / B11 and f^2 = (B33 - (B13^2 + B23^2) /
//   B11) / B11. It put the principal point of a 1920 x 200 strip ~400 px
//   below it within 70 px, and that of a 640 x 480 window at the corner
//   above within 60 px, but has no real solution (f^2 < 0) for the 320 x
//   240 one: under 20 deg of a distorted lens's field, 43 deg off its axis;
// - the principal point at the centre, with OpenCV's focal length (the seed
//   before windows were considered: kept unless another candidate's RMS is
//   under 0.2 x its own, see pinhole_seed.cc for the figures), and with
//   focal lengths from half the image's width to 16 times it, a factor
//   sqrt(2) apart (for a 640 px window: 320, 453, 640, 905, 1280, 1810 px,
//   ...). Their purpose: from a centred principal point, mrcal converges
//   when the focal length is roughly right.
// Measured on the windows of calib/intrinsics_window_test.cc. The best by
// this RMS is not always the one mrcal converges from (behind a 320 x 240
// corner window, 15 of 40 seeds' captures failed from it, and 10 of those
// converged from another, often a far-off focal length of the ladder), so
// stage 1 solves from every candidate when the first fails
// (RankedPinholeSeeds, calib/intrinsics.h).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "calib/core/pose.h"
#include "calib/observations.h"

namespace stereorig {

struct PinholeSeed {
  double focal_px = 0;
  Eigen::Vector2d principal_point_px = Eigen::Vector2d::Zero();  // (cx, cy), image coordinates; may be off the image
};

// One view's corners: on the board (mm, the face's frame) and in the image
// (px), as OpenCV's PnP takes them.
struct ViewCorners {
  std::vector<cv::Point3d> board_mm;
  std::vector<cv::Point2d> image_px;
};
ViewCorners CornersOfView(const BoardObservation& view, const TargetGeometry& target);

// The board's pose in the camera, cam_from_face, from PnP (IPPE) through the
// distortion-free pinhole `seed`; nullopt if PnP fails: OpenCV returns false
// for a row of corners and one beside it, and true with a NaN pose for
// corners on one line (measured, 11 x 9 board).
std::optional<Pose> PinholeBoardPose(const ViewCorners& corners, const PinholeSeed& seed);

// The candidates, the centred seed (the image's centre with OpenCV's focal
// length, or the given one) first; none repeats another.
std::vector<PinholeSeed> PinholeSeedCandidates(const std::vector<const BoardObservation*>& views,
                                               const TargetGeometry& target, int width_px, int height_px,
                                               double given_focal_px);

// `views`: one camera's observations, each with corners spanning the board's
// plane. `given_focal_px` > 0 is every candidate's focal length (the user's
// rough value); the principal point is still chosen. The candidates, the
// chosen one first (below), then the others by their RMS, lowest first.
std::vector<PinholeSeed> RankedPinholeSeeds(const std::vector<const BoardObservation*>& views,
                                            const TargetGeometry& target, int width_px, int height_px,
                                            double given_focal_px);

// The one of RankedPinholeSeeds stage 1 starts from.
PinholeSeed EstimatePinholeSeed(const std::vector<const BoardObservation*>& views, const TargetGeometry& target,
                                int width_px, int height_px, double given_focal_px);

}  // namespace stereorig
