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
// (SystemReport::solver_problem; with more than one module, once stage 2
// ran).
// Else one line naming the earliest stage over it, each of its cameras or
// modules (stage 3: its worst captures against the median capture), its
// figure and what usually causes it, for the message refusing the rig file.
std::string NotConvergedProblem(const CalibrationReport& report, double max_rms_px);

}  // namespace stereorig
