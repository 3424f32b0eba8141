// Did each stage of a calibration converge? A stage whose reprojection RMS
// is far above the corners' noise did not: its lens, pose or S is wrong by
// more than any figure it reports. Such a calibration is not written
// (calibrate.h, WriteCalibrationOutputs), as a lens no camera has is not.
//
// Why a limit on the RMS: a 640 x 480 window at the corner of a 2448 x 2048
// sensor (docs/calibration.md, "Windowed sensors") left stage 1 at
// rms 25.5 px with 23 outliers, every lens figure plausible, and the rig
// file was written; and synthetic corners seen through a 320 x 240 window at
// the corner of a 1920 x 1200 sensor leave 3 of 40 seeds at 5.5-34 px from
// every seed candidate stage 1 tries (calib/intrinsics.h; IntrinsicsWindow.
// EverySeedIsTriedBeforeACameraIsNamedAsNotConverged, calib_e2e_test). A
// converged camera's RMS is its corners' noise and its lens model's misfit:
// 0.02 px on the rendered default dataset, 0.19 px for 0.2 px of synthetic
// noise. Not measured here on a real lens: one that LENSMODEL_OPENCV5 holds
// badly (a wide angle) may stay over 1 px though converged; such a user
// chooses a richer model (--lensmodel) or raises the limit.
#pragma once

#include <string>

#include "calib/calibrate.h"

namespace stereorig {

// "" if every stage is within `max_rms_px`: each camera's stage 1 RMS
// (inlier corners), each module's stage 2 RMS, and stage 3's RMS and its
// median corner residual distance (against sqrt(2 ln 2) max_rms_px, the
// median distance of Gaussian residuals of that RMS per coordinate), and
// stage 3's solve ended at Ceres's CONVERGENCE with its residuals evaluated
// (SystemReport::solver_problem), and each camera's stage 3 residuals are
// the noise stage 2 measured on it (kStage3ExcessFloorOfLimit) (stage 3's:
// with more than one module, once stage 2 ran).
// Else one line naming the earliest stage over it, each of its cameras or
// modules (stage 3: its worst captures against the median capture), its
// figure and what usually causes it, for the message refusing the rig file.
std::string NotConvergedProblem(const CalibrationReport& report, double max_rms_px);

// The warning of a stage 3 whose Horn-only solve (S and the stereo pairs
// held, the board poses solved) stopped short or whose residuals could not
// be evaluated (SystemReport::horn_only_solver_problem), each said for what
// happened: its rms is where it stopped, or not a number. "" if neither.
std::string HornOnlyWarning(const SystemReport& system);

// For Gaussian residuals of sigma per coordinate the distance hypot(du, dv)
// is Rayleigh: its q-quantile is sigma sqrt(-2 ln(1 - q)). The median:
// sqrt(2 ln 2) = 1.1774 sigma; the 90th percentile: sqrt(2 ln 10) = 2.1460
// sigma.
inline constexpr double kRayleighMedian = 1.1774100225154747;
inline constexpr double kRayleighP90 = 2.1459660262893472;

// Stage 3 against the noise stage 2 measured (the rule after the limit).
// A module's two cameras are rigid to each other, so stage 2, which gives
// every capture its own board pose per module, fits a module that moved
// between captures at the corners' noise; only stage 3, one S over every
// capture, cannot. Such a move puts stage 3's residuals at the size of
// noise the limit passes: module 1 of the default rig moved 1 mm across
// after 10 of 20 captures left stage 3 at rms 0.88 px, median 1.02 px, at
// 0.2 px of noise (stage 2: 0.196 px), each camera's distances Rayleigh-
// shaped (median 1.17, 90th percentile 2.05 - 2.17 times the rms), like
// honest noise of 0.88 px, which the limit of 1 px must pass. So each
// camera of stage 3 is held to its own stage 2 noise sigma: its median and
// 90th percentile distance against the Rayleigh quantiles of a spread
// sqrt(sigma^2 + e^2), e = max(sigma, kStage3ExcessFloorOfLimit x the
// limit): a misfit stage 3 adds as large as the noise is allowed (the
// variance doubled: honest data read 1.00 - 1.02 times stage 2's rms,
// rendered or synthetic, and the median of 1000 corners scatters by ~3%,
// so honest data sit ~14 of its sigmas inside the limit: 40 honest
// calibrations of the default rig, 25 captures at 0.2 and 0.5 px, read at
// most 0.74 of it, none refused; the margin is for
// what real data may add that stage 2 does not see, the modules' exposures
// a little apart, a board that bends). The floor: at the rendered images'
// noise of 0.02 px, doubling the variance would refuse a misfit of 0.03 px
// (6 um across the ray at 200 mm), far below what the rig file's users
// measure; a tenth of the limit is what is not refused whatever the noise.
// A policy, not derived.
inline constexpr double kStage3ExcessFloorOfLimit = 0.1;

// One camera's stage 3 limits by that rule: its stage 2 noise sigma (0 where
// stage 2 gave none: no limit), and the median and 90th percentile corner
// distance allowed, px. The floor, when it sets them (sigma under it), is
// said with them: "that noise and as much again" alone quoted limits 3.3 -
// 3.6 times what it gives on the rendered images (0.020 - 0.022 px).
struct Stage3CameraLimits {
  double sigma_px = 0.0;
  double median_px = 0.0;
  double p90_px = 0.0;
  double floor_px = 0.0;         // kStage3ExcessFloorOfLimit x the limit
  bool floor_sets_them = false;  // the excess is the floor, not sigma
};
Stage3CameraLimits Stage3CameraLimitsOf(const CalibrationReport& report, int camera, double max_rms_px);

}  // namespace stereorig
