// Hole filling from an a-priori shape model: the model is fitted robustly to
// the merged cloud, and its surface closes what no module saw.
//
// Sphere: RANSAC + geometric Gauss-Newton (metrology/sphere_fit.h). The
// sphere is sampled on a (polar, azimuth) lattice at fill_spacing_mm; a
// sample is kept where the cloud has no point within 2 spacings, and the
// lattice cells whose four corners are kept become mesh triangles. Filled
// points carry module = kFilledModule and confidence 0.
// Cylinder and ellipsoid models are not built yet (RuntimeOptions::Check
// rejects them).
#pragma once

#include <string>

#include "reconstruct/point_cloud.h"
#include "reconstruct/runtime_options.h"

namespace stereorig {

struct HoleFillResult {
  bool ok = false;
  int added_points = 0;
  std::string message;  // the fitted model, or why nothing was filled
};

// Fits the model to `measured`, appends the fill to *cloud and *mesh (either
// may be the same object as `measured`'s owner; `measured` is read first).
HoleFillResult FillHolesFromModel(const PointCloud& measured, const RuntimeOptions& options, PointCloud* cloud,
                                  Mesh* mesh);

}  // namespace stereorig
