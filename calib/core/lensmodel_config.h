// A splined lens model's configuration, judged before mrcal sees it.
//
// mrcal parses LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=50
// into 16-bit numbers without a range check, and judges them only when it
// first projects, then by assert (SIGABRT, for an Nx or Ny under its
// minimum or an order other than 2 or 3), or not at all (a field of view of
// 0 or 400 deg gives a spline with no extent, or a negative one). Every
// reader of a lens model judges it here: calibrate --lensmodel
// (calib/intrinsics.h), a rig file's cameras (rig_file.h), a simulator
// spec's (datasets/sim_spec.h), and every Camera (camera.h).
#pragma once

#include <string>

namespace stereorig {

// What is wrong with a splined model's configuration, starting with the
// name quoted ("'LENSMODEL_...': Nx=1 Ny=1: an order 3 spline needs ..."),
// or "" (a good one, any other model, a name mrcal does not know).
std::string LensmodelConfigProblem(const std::string& lensmodel_name);

}  // namespace stereorig
