// VDI/VDE 2634 Part 2 acceptance figures from a measured point cloud of a
// reference artifact:
//   - probing error form P_F: the range of radial residuals of a
//     least-squares sphere with free radius;
//   - probing error size P_S: fitted diameter minus certified diameter;
//   - sphere-spacing error SD: measured minus certified centre distance;
//   - flatness F: the range of residuals to the least-squares plane.
// Each is judged against the artifact's maximum permissible error (MPE).
//
// Fitting is robust: RANSAC segments the artifact's points (points farther
// than the MPE from every consensus shape are not on the artifact), then a
// least-squares fit on all of them. As the standard allows, up to 0.3% of the
// artifact's points - those with the largest residuals - are excluded before
// the figures are computed; the report says how many. The fit never uses the
// reconstruction's own shape prior.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "reconstruct/metrology/artifact.h"

namespace stereorig {

struct VerifyOptions {
  double excluded_fraction_max = 0.003;  // the standard's 0.3%
  // RANSAC inlier band, mm; <= 0 means "the MPE of the figure" (a point
  // farther than the MPE from the artifact cannot be part of a passing one).
  double segmentation_band_mm = 0;
  int min_points = 200;  // fewer points on the artifact: bad input
  // Ball bar: each ball's points within this angle of the bar axis (towards
  // the other ball) belong to the shaft's neighbourhood and are not used.
  double ballbar_shaft_cone_deg = 60.0;
  // Plate: the face is evaluated inside its outline eroded by this border,
  // so the edges and sides (chamfers, the plate's thickness) are not.
  double plate_edge_margin_mm = 5.0;
  unsigned seed = 1;
  void Check() const;
};

struct Figure {
  std::string name;  // "P_F", "P_S", "SD", "F"
  double value_mm = 0;
  double mpe_mm = 0;
  bool pass = false;  // |value| <= mpe
};

struct ArtifactEvaluation {
  ArtifactType type = ArtifactType::kSphere;
  int points_total = 0;        // in the cloud
  int points_on_artifact = 0;  // after segmentation
  int points_excluded = 0;     // the standard's <= 0.3%
  std::vector<Figure> figures;
  // Residuals to the fitted shape(s) after exclusion, as the seed reports them.
  double residual_mean_abs_mm = 0;
  double residual_std_mm = 0;
  // The fitted geometry.
  std::vector<Eigen::Vector3d> sphere_centers_mm;  // 1 (sphere) or 2 (ball bar)
  std::vector<double> sphere_diameters_mm;
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  double plane_offset_mm = 0;
  bool pass() const;
};

// Throws InputError(`where`, ...) when the cloud has too few points on the
// artifact, or the artifact cannot be found in it.
ArtifactEvaluation EvaluateArtifact(const Artifact& artifact, const std::vector<Eigen::Vector3d>& points_mm,
                                    const VerifyOptions& options, const std::string& where);

// Several positions of the same artifact: per figure, the worst |value|.
struct VerifySummary {
  std::vector<Figure> worst;  // one per figure name, the position with the largest |value|
  bool pass = false;
};
VerifySummary Summarise(const std::vector<ArtifactEvaluation>& positions);

}  // namespace stereorig
