// What changed in a camera that no longer agrees with the others: did it
// move, or did its lens drift (a focus ring turned or thermal drift scaling
// the focal length, a knock moving the principal point)?
//
// Both are fitted to the camera's corners, with the board poses the other
// cameras imply held fixed:
//   - moved: its pose cam_from_ref refitted (6 parameters), lens as stored;
//   - lens:  its focal length (fx and fy by one factor) and principal point
//            refitted (3 parameters), pose as stored.
// A change is what explains the corners: a fit whose residual RMS passes the
// camera's consistency threshold (the same k-sigma bound, from the stored
// calibration, that flagged it). Where both fit, the check cannot tell them
// apart and says so: a principal-point shift of d px looks, to first order,
// like a turn of d / f rad about the image's other axis, and a focal change
// like a shift along the optical axis when the board stays at one depth.
// Where neither fits, it says that, and no more: the camera moved and its
// lens changed, or something neither fit frees changed (its distortion, its
// sensor), or the threshold was passed by chance.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "calib/observations.h"
#include "targets/target.h"

namespace stereorig {

enum class CameraChangeKind {
  kMoved,        // only a new pose explains its corners
  kLens,         // only a new focal length and principal point explain them
  kMovedOrLens,  // either explains them: the check cannot tell which
  kUnexplained,  // neither alone explains them (above: what may have changed)
  kNotFitted,    // too few corners to fit either (fewer than kMinCornersToFit)
};

// The kind's name in the JSON report: "moved", "lens", "moved_or_lens",
// "unexplained", "not_fitted".
const char* CameraChangeKindName(CameraChangeKind kind);

// Fewer corners than this fit neither change: the pose fit has 6 unknowns.
constexpr int kMinCornersToFit = 6;

struct CameraChange {
  int camera = -1;
  CameraChangeKind kind = CameraChangeKind::kNotFitted;
  int corners = 0;  // behind both fits
  // Per axis; NaN when not fitted; +inf when the pose fit's solve failed.
  double moved_rms_px = 0;  // with the pose refitted
  double lens_rms_px = 0;   // with the lens refitted
  double threshold_px = 0;  // what either must pass to explain the corners
  // The lens fit's estimate: fx and fy scaled by 1 + focal_percent / 100,
  // (cx, cy) moved by principal_point_px.
  double focal_percent = 0;
  Eigen::Vector2d principal_point_px = Eigen::Vector2d::Zero();
  // The pose fit's estimate: how far the camera turned (deg) and shifted
  // (mm) from its stored pose; NaN when not fitted or the solve failed.
  double turned_deg = 0;
  double shifted_mm = 0;
  // The centre's shift as a vector in the reference frame (shifted_mm is
  // its length); NaN where shifted_mm is.
  Eigen::Vector3d shift_mm = Eigen::Vector3d::Zero();
  // Where it sits: "module 0's right camera" (the rig's modules).
  std::string role;
  // "camera 2 moved: turned 0.050 deg, shifted 0.004 mm", "camera 2's lens
  // changed: ...", "camera 2 moved or its lens changed (either explains its
  // corners): turned 0.050 deg, shifted 0.004 mm, or focal length +0.012 %,
  // principal point +0.05, -0.01 px", "camera 2 changed: neither a new pose nor a new lens alone
  // explains its corners (...)", "camera 2 changed: too few corners (N) to
  // fit a new pose or a new lens"; each followed by the role, " [module 1's
  // left camera]", where it has one.
  std::string Describe() const;

 private:
  std::string DescribeChange() const;  // Describe() without the role
};

// One view of camera `camera` with the board pose the other cameras imply.
struct PosedView {
  const BoardObservation* view;
  Pose ref_from_front;
};

// The per-axis RMS of `corners` corners' residuals whose squares sum to
// sum_of_squares (two axes a corner): the figure every fit here is judged by.
double RmsPerAxis(double sum_of_squares, size_t corners);

// The residual (px) of a corner at p_cam (the camera's frame) seen at q by
// `camera` with its lens drifted by lens = (s, dx, dy) (DriftedPixel,
// calib/core/lens_drift.h), for the Ceres cost functors of the check's fits
// that free a lens; false behind the camera.
bool DriftedLensResidual(const Camera& camera, const Eigen::Vector3d& p_cam, const double* lens,
                         const Eigen::Vector2d& q, double* residual);

// Where `camera` sits on `rig`: "module 0's right camera" (empty if no
// module holds it).
std::string CameraRole(const Rig& rig, int camera);

// `views` are the camera's views, each with the pose from the others;
// `threshold_px` its consistency threshold (per-axis RMS).
CameraChange ExplainCameraChange(const Rig& rig, const Target& target, int camera, const std::vector<PosedView>& views,
                                 double threshold_px);

}  // namespace stereorig
