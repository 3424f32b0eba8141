// Did each stage of a calibration converge? A stage whose reprojection RMS
// is far above the corners' noise did not: its lens, pose or S is wrong by
// more than any figure it reports. Such a calibration is not written
// (calibrate.h, WriteCalibrationOutputs), as a lens no camera has is not.
//
// Why a limit on the RMS: a 640 x 480 window at the corner of a 2448 x 2048
// sensor (docs/calibration.md, "Windowed sensors") left stage 1 at
// rms 25.5 px with 23 outliers, every lens figure plausible, and the rig
// file was written; and synthetic corners seen through a 320 x 240 window at
// the corner of a 1920 x 1200 sensor leave some seeds at 1.6-62 px
// (IntrinsicsWindow.AStageOneThatDidNotConvergeIsNamed). A converged
// camera's RMS is its corners' noise: 0.02 px on the rendered default
// dataset, 0.19 px for 0.2 px of synthetic noise; a real camera's corners
// are found to a few tenths of a pixel.
#pragma once

#include <string>

#include "calib/calibrate.h"

namespace stereorig {

// "" if every stage's RMS is within `max_rms_px`: each camera's stage 1 RMS
// (inlier corners), each module's stage 2 RMS, and stage 3's refined RMS
// (with more than one module). Else one line naming each stage over it, its
// RMS and what usually causes it, for the message refusing the rig file.
std::string NotConvergedProblem(const CalibrationReport& report, double max_rms_px);

}  // namespace stereorig
