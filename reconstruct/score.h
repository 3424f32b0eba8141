// Scoring a reconstructed cloud against a dense truth surface, independently
// of how the cloud was made: one best rigid alignment (no scale) of the
// whole cloud to the truth, then each point's distance to the truth surface.
//
// The truth is a set of dense surface samples (the simulator's surface.ply,
// <= 0.2 mm apart). A point's distance to the surface is taken to the plane
// fitted through its 8 nearest truth samples (k-d tree): the nearest sample
// alone would add up to half the sample spacing to every error.
// The alignment is point-to-plane ICP from the identity (the calibrated
// reference frame differs from the truth by a small rigid motion), pairs
// whose nearest truth sample is farther than 2 mm left out.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/core/pose.h"
#include "reconstruct/point_cloud.h"

namespace stereorig {

struct ErrorFigures {
  int points = 0;
  double mean_abs_mm = 0;  // mean |distance|
  double mean_mm = 0;      // signed (outside the surface = positive, along the truth normal's side)
  double std_mm = 0;
  double rms_mm = 0;
  double p95_abs_mm = 0;
  double max_abs_mm = 0;
  double within_0_5_mm = 0;  // fraction of points with |distance| <= 0.5 mm (issue 5's bound for the fill)
};

// The fill's figures for the filled points whose nearest measured point is
// [from_mm, to_mm) away: how far the fill extrapolates from what was seen.
struct FillBand {
  double from_mm = 0, to_mm = 0;  // to_mm = infinity for the last band
  ErrorFigures figures;
};

struct CloudScore {
  Pose truth_from_cloud;                     // the best rigid alignment
  ErrorFigures all;                          // measured points (filled ones excluded)
  std::vector<ErrorFigures> per_module;      // index = module
  ErrorFigures filled;                       // hole-filling points (module kFilledModule), if any
  std::vector<FillBand> filled_by_distance;  // the same by distance to the nearest measured point: 0-5, 5-15, >= 15 mm
};

// `truth`: (N) samples in mm. `num_modules`: size of per_module.
CloudScore ScoreAgainstTruth(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& truth, int num_modules);

// The same figures under a given alignment, found for another cloud of the
// same rig and scene (CloudScore::truth_from_cloud): score judges the passive
// capture's points under the active cloud's alignment, which a cloud of
// gross mismatches would pull off its own.
CloudScore ScoreUnderAlignment(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& truth,
                               const Pose& truth_from_cloud, int num_modules);

// The share, in [0, 1], of `points_mm` inside the axis-aligned box of size
// `size_mm` centred on `centre_mm` (faces included); 0 for no point. Score
// uses it on a scene's truth surface and the measurement volume: a volume
// that misses the object scores an empty cloud, which must not pass silently.
double ShareInsideBox(const std::vector<Eigen::Vector3d>& points_mm, const Eigen::Vector3d& centre_mm,
                      const Eigen::Vector3d& size_mm);

}  // namespace stereorig
