// Runtime options: what the runtime knows a priori about the scene, and how
// hard it works. Read from YAML (docs/reconstruct.md lists every key); a
// missing key takes the default below, an unknown key is an error.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "reconstruct/free_space.h"
#include "reconstruct/matcher.h"

namespace stereorig {

enum class ShapeModel { kNone, kSphere, kCylinder, kEllipsoid };
ShapeModel ParseShapeModel(const std::string& name, const std::string& where);
const char* ShapeModelName(ShapeModel model);

struct RuntimeOptions {
  // The measurement volume: an axis-aligned box in the reference frame
  // (module 0's frame), mm. Every module's disparity search range and region
  // of interest are derived from it. Default centre: working_distance_mm in
  // front of module 0's baseline midpoint, along the mean of its two
  // optical axes.
  std::optional<Eigen::Vector3d> volume_center_mm;  // default: see working_distance_mm
  // Only used to place the default volume centre; default 200 (the seed's).
  // An options file giving it with volume_center_mm is refused.
  double working_distance_mm = 200.0;
  Eigen::Vector3d volume_size_mm = Eigen::Vector3d(150, 150, 100);  // default 150 x 150 x 100 (the seed's)
  // Largest dimension of the objects measured (the largest distance between
  // two of their points), mm. Used against two different lengths:
  //  - points (runtime.cc): in each module, a point (inside the volume, with
  //    confidence >= min_confidence) whose 3D distance from the per-axis
  //    median of that module's points exceeds this is dropped
  //    (PixelStatus::kObjectSize: background, gross mismatches). A radius of
  //    object_size_mm around a point on or near the object: it does not
  //    check the object's size, and an object up to ~2x this across can
  //    keep every point;
  //  - the shape model (hole_fill.cc): refused if its full extent exceeds
  //    this: a sphere's or cylinder's diameter, a cylinder's length, an
  //    ellipsoid's longest axis (RANSAC already skips cylinder radii and
  //    ellipsoid semi-axes above it).
  // So an object larger than this can keep its points and yet have its
  // fitted model refused.
  double object_size_mm = 100.0;  // default 100
  // Crop each capture's ROI to the bounding box of the laser-lit area (active
  // mode): the grid lights ~81x81 mm at 200 mm, a quarter of the image.
  bool crop_to_lit_region = true;  // default true
  double lit_contrast_dn = 12.0;   // a pixel is "lit" if its 9x9 grey-level std exceeds this; default 12 DN
  MatchOptions match;              // matcher; its range and ROI are derived per module (ignored here)
  // Per-point confidence below which a point is dropped, [0, 1].
  double min_confidence = 0.5;    // default 0.5 (below match.min_zncc's 0.8, which usually bites first)
  int normal_step_px = 2;         // normals from neighbours +-this many px in the depth grid; default 2
  double mesh_max_edge_mm = 1.5;  // organised mesh: no triangle edge longer than this (depth jumps); default 1.5
  ShapeModel shape_model = ShapeModel::kNone;  // hole filling model; default none
  double fill_spacing_mm = 1.0;                // hole filling: sample spacing on the model surface; default 1.0 mm
  // Hole filling follows what the model misses: the measured points'
  // residuals to the model, as a smooth field (residual_field.h), move each
  // fill sample along the model's normal; far from the data the fill returns
  // to the model. Off (the field is zero) where the model is exact to the
  // noise (residual rms < 0.1 mm: a sphere, a cup). Default true.
  bool fill_follow_residuals = true;
  // The field's length scale, mm: about the size of the object's features
  // the fill should follow. 0 (default) = chosen from the data, of 6-30 mm:
  // the one that best predicts the residuals left out a block at a time
  // (residual_field.h).
  double fill_residual_length_mm = 0;
  bool parallel_modules = true;  // the modules in parallel on the runtime's worker pool (parallel_for.h); default true
  // The free-space test across modules (free_space.h): a module's point is
  // removed (status kSeenThrough) where the other modules' surfaces facing
  // its left camera lie in front of it along its ray. Only with 2+ modules.
  bool free_space_test = true;  // default true
  FreeSpaceOptions free_space;  // its thresholds (free_space.h)

  // Where these options came from (the YAML file's path; empty for the
  // built-in defaults), for messages about them that only the Runtime can
  // give (a volume this rig cannot see or search). Not a YAML key.
  std::string source;
  // "runtime options", or "<source> (runtime options)": the `where` of such messages.
  std::string Where() const { return source.empty() ? "runtime options" : source + " (runtime options)"; }

  void Check() const;  // throws InputError naming the bad key
};

// Reads a runtime options YAML file (keys: docs/reconstruct.md).
RuntimeOptions ReadRuntimeOptions(const std::string& path);

// `active` for a capture without the laser grids (passive), so that the two
// run the same pipeline: the grid's own steps off, the rest as given. No
// crop to the lit region (the whole volume's ROI); no distinctness test half
// a grid period off; no grid-line test; no line index (which laser line is
// which: without lines its vernier reads noise, and on the demo cup it
// dropped a third of module 0's pixels as wrong_line, every point).
RuntimeOptions PassiveOptions(RuntimeOptions active);
// Whether the grid's own steps are all off, as PassiveOptions sets them: the
// options of a capture without the laser grid, whose "lit" pixels are those
// the ambient light gives contrast (9x9 std above lit_contrast_dn), no grid.
bool IsPassive(const RuntimeOptions& options);
RuntimeOptions ParseRuntimeOptions(const std::string& text, const std::string& where);

}  // namespace stereorig
