// Hole filling from an a-priori shape model (RuntimeOptions::shape_model):
// the model is fitted robustly to the merged cloud (reconstruct/metrology:
// sphere, cylinder from oriented points, ellipsoid), and its surface closes
// what no module saw.
//
// The model's surface is sampled on a closed (row, column) lattice at
// fill_spacing_mm: sphere and ellipsoid by (polar, azimuth), the cylinder's
// lateral surface over the inliers' axial extent by (axial, angle).
// With fill_follow_residuals, each sample then moves along the model's
// normal by what the model misses there: the measured points' signed
// distances to the model (along its normal; on the ellipsoid, along the
// normal of the level set through the point, exact to second order),
// interpolated by a Gaussian process (residual_field.h). Near the data the
// fill follows the real surface (a tuber's bumps), far from it it returns
// to the model; where the model is exact (residual rms < 0.1 mm) nothing
// moves. A sample is kept where the cloud has no point within 2 spacings
// (proximity_grid.h), and the lattice cells whose corners are kept become
// outward-facing triangles. Filled points carry module = kFilledModule and
// confidence 0.
//
// The fit runs on every k-th point of `measured` (k = size / 20000, at
// least 1). A fit is not used (ok = false, message says why, nothing added)
// if it fails, if the model is larger than object_size_mm (its diameter,
// length or longest axis), or if fewer than half of the points fitted (the
// subsample) are its inliers. The "N inliers" of the message counts points
// of that subsample.
#pragma once

#include <string>

#include "reconstruct/point_cloud.h"
#include "reconstruct/runtime_options.h"

namespace stereorig {

struct HoleFillResult {
  bool ok = false;
  int added_points = 0;
  std::string message;  // the fitted model and the residual field, or why nothing was filled
};

// Fits the model to `measured`, appends the fill's points to *cloud and its
// triangles, over those points (indices into *cloud), to *mesh. `measured`
// may be *cloud itself (it is read first).
HoleFillResult FillHolesFromModel(const PointCloud& measured, const RuntimeOptions& options, PointCloud* cloud,
                                  Mesh* mesh);

}  // namespace stereorig
