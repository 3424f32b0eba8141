// VDI/VDE 2634 Part 2 acceptance figures from a measured point cloud of a
// reference artifact:
//   - probing error form P_F: the range of radial residuals of a
//     least-squares sphere with free radius;
//   - probing error size P_S: fitted diameter minus certified diameter;
//   - sphere-spacing error SD: measured minus certified centre distance;
//   - flatness F: the range of residuals to the least-squares plane.
// Each is judged against the artifact's maximum permissible error (MPE).
//
// Which points are the artifact's is decided in two steps. RANSAC *locates*
// the shape with a narrow band (the MPE): a consensus of points measured
// within the MPE. Then every point within the much wider *capture band* of the
// located shape (5 mm by default, never less than twice the MPE) is the
// artifact's, and all of them enter the least-squares fit and the figures: the
// runtime's known gross error, a patch one laser-grid period off, is ~3.5 mm
// deep (docs/reconstruct.md), and a band that left it out would hide exactly
// the error the figures must show. A part of the artifact measured beyond
// the band (a patch further off, where the artifact's surface is missing
// among measured surface: surface_beyond_band.h) leaves a position that
// would pass not judged. As the standard allows, up to 0.3% of the
// artifact's points - those with the largest residuals - are excluded before
// the figures are computed; the report says how many. A shape that does not
// cover the certified artifact plausibly (a plane much smaller or larger than
// the plate) is refused. The fit never uses the reconstruction's own shape
// prior: the caller leaves out hole filling's points (ply_points.h).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/metrology/artifact.h"
#include "reconstruct/metrology/decision_rule.h"

namespace stereorig {

struct VerifyOptions {
  double excluded_fraction_max = 0.003;  // the standard's 0.3%
  // RANSAC's inlier band, mm, which only locates the shape; <= 0 means "the
  // MPE of the figure" (a consensus of points measured within the MPE). For a
  // sphere or a ball bar's balls either is capped at an eighth of the
  // certified radius (vdi2634.cc, kMaxLocateBandOfRadius), this value too:
  // wider, another object passed for the artifact.
  double locate_band_mm = 0;
  // The artifact's points: those within this distance of the located shape,
  // mm, iterated with the least-squares fit to a fixed point. Used as
  // max(capture_band_mm, 2 * MPE): narrower, an error beyond the MPE would be
  // cut off before the figures see it. 5 mm holds a patch one grid period off
  // (~3.5 mm) with room for the fit's shift, and stays clear of the far face
  // of the simulator's 8 mm plate.
  double capture_band_mm = 5.0;
  int min_points = 200;  // fewer points on the artifact: not the artifact (verify: that position not evaluated)
  // Ball bar: each ball's points within this angle of the bar axis (towards
  // the other ball) belong to the shaft's neighbourhood and are not used.
  double ballbar_shaft_cone_deg = 60.0;
  // Plate: the face is evaluated inside its outline eroded by this border,
  // so the edges and sides (chamfers, the plate's thickness) are not.
  double plate_edge_margin_mm = 5.0;
  // Plate: the plane found must span at least this fraction of the certified
  // length and of the width (and at most the certified size plus twice the
  // capture band), or it is not the plate.
  double plate_min_coverage = 0.5;
  // P_S (sphere), SD (ball bar) and F (plate) must be determined to a
  // standard uncertainty (k = 1; the fit's covariance, sphere_uncertainty.h,
  // and the certificate's, combined: Figure) of at most this fraction of
  // their MPE, or a position that would pass is refused (one that fails
  // beyond doubt is judged: another figure fails, or this one by more than
  // 2u): a small cap's fitted diameter is noise, not the system's size error,
  // and a figure taken against a reference known to no better than the
  // tolerance says nothing of the system. 0.1 keeps the expanded uncertainty
  // (k = 2) within a fifth of the MPE, so the verdict is the figure's, not
  // the fit's or the certificate's. Measured basis: 2000 points of a
  // 38.1 mm sphere with the runtime's 0.05 mm noise fit its diameter to
  // 0.005 mm over a hemisphere, 0.12 mm over a 20-degree cap and 0.5 mm over
  // a 10-degree cap (sphere_uncertainty_test.cc; docs/verify-and-check.md).
  double max_uncertainty_fraction_of_mpe = 0.1;
  // How a figure and its expanded uncertainty U = 2u are judged against the
  // MPE (decision_rule.h, ISO 14253-1): simple acceptance (|value| <= MPE,
  // the default), guarded acceptance (|value| + U <= MPE) or guarded
  // rejection (fail only if |value| - U > MPE). A figure without u (P_F
  // without the certificate's form_uncertainty_mm, F without its
  // flatness_uncertainty_mm) is judged with U = 0 by every rule. A figure
  // the refusal above leaves undetermined is judged only where its failure
  // stands (simple acceptance: |value| - 2u > MPE; guarded acceptance: any
  // failure; guarded rejection: |value| - 2u > MPE where u is the figure's,
  // its fit's part within the limit and the certificate's stated U putting
  // it over; never where the fit's part is over the limit itself, a floor
  // that a larger u could undo), and its pass never.
  DecisionRule decision_rule = DecisionRule::kSimpleAcceptance;
  unsigned seed = 1;
  void Check() const;
};

struct Figure {
  std::string name;  // "P_F", "P_S", "SD", "F"
  double value_mm = 0;
  double mpe_mm = 0;
  bool pass = false;  // within the MPE under VerifyOptions::decision_rule (simple: |value| <= mpe)
  // Whether `pass` stands: the figure is determined (its u within
  // VerifyOptions::max_uncertainty_fraction_of_mpe of its MPE, or it has no
  // u), or its failure stands without it (vdi2634.cc, FailureStands: under
  // simple acceptance beyond the MPE by more than its stated 2u, under
  // guarded acceptance any failure, under guarded rejection beyond it by
  // more than 2u unless u is a floor). A figure not judged is reported, its
  // pass not claimed.
  bool judged = true;
  // A figure left undetermined whose u is a floor, not its error: its fit's
  // part is itself over the limit, or not positive and finite (vdi2634.cc,
  // UncertaintyIsAFloor). False where the certificate's stated U puts u over
  // the limit, and for a determined figure.
  bool uncertainty_is_floor = false;
  // value_mm's standard uncertainty (k = 1): its two parts below combined in
  // quadrature, u = sqrt(u_fit^2 + u_certificate^2) (independent sources:
  // the measurement's noise, the reference's calibration; VDI/VDE 2634-2 and
  // ISO 10360 count the artifact's calibration uncertainty in the test's).
  // P_S and SD have both; F and P_F the certificate's alone (a range of
  // residuals has no fit covariance; P_F's is the sphere's certified form,
  // form_uncertainty_mm, not its size: the form is measured against the
  // sphere's own fit). Absent where neither part is (an exact certificate
  // leaves a range without one, not with 0).
  std::optional<double> standard_uncertainty_mm;
  // From the fit's covariance (sphere_uncertainty.h): P_S, SD.
  std::optional<double> fit_standard_uncertainty_mm;
  // The certificate's U / k of the certified value the figure is taken
  // against: the diameter (P_S), the centre distance (SD), the flatness (F);
  // for P_F the sphere's certified form.
  std::optional<double> certificate_standard_uncertainty_mm;
  // U = kDecisionCoverageFactor * u, what the guarded rules read; 0 without u.
  double ExpandedUncertaintyMm() const {
    return standard_uncertainty_mm ? kDecisionCoverageFactor * *standard_uncertainty_mm : 0.0;
  }
  // ISO 14253-1's zone of value_mm against mpe_mm with that U; none
  // without u (a figure whose uncertainty is unknown is in no proven zone).
  std::optional<ConformanceZone> zone() const {
    if (!standard_uncertainty_mm) return std::nullopt;
    return ZoneOf(value_mm, ExpandedUncertaintyMm(), mpe_mm);
  }
};

struct ArtifactEvaluation {
  ArtifactType type = ArtifactType::kSphere;
  // Every given point is counted once: points_total = points_off_artifact +
  // points_in_edge_margin + points_on_artifact, and points_on_artifact =
  // points_excluded + points_used().
  int points_total = 0;        // given (the measured points of the cloud)
  int points_on_artifact = 0;  // within the capture band (and, plate, the eroded outline; ball bar, off the shaft)
  int points_excluded = 0;     // the standard's <= 0.3% of points_on_artifact
  // Not the artifact's: outside the capture band; ball bar: also those in
  // the shaft's cone; plate: also those captured but outside its outline.
  int points_off_artifact = 0;
  // Plate: captured, inside its outline but within plate_edge_margin_mm of
  // it (the sides and chamfers, not evaluated). 0 for the others.
  int points_in_edge_margin = 0;
  double capture_band_mm = 0;  // the band used (VerifyOptions::capture_band_mm, at least 2 * MPE)
  int points_used() const { return points_on_artifact - points_excluded; }
  std::vector<Figure> figures;
  DecisionRule decision_rule = DecisionRule::kSimpleAcceptance;  // VerifyOptions::decision_rule, as judged
  // Residuals to the fitted shape(s) after exclusion, as the seed reports them.
  double residual_mean_abs_mm = 0;
  double residual_std_mm = 0;
  // The fitted geometry.
  std::vector<Eigen::Vector3d> sphere_centers_mm;  // 1 (sphere) or 2 (ball bar)
  std::vector<double> sphere_diameters_mm;
  // Per sphere, parallel: how much of it the points cover and how well they
  // fit its diameter (sphere_uncertainty.h).
  std::vector<double> sphere_cap_half_angles_deg;
  std::vector<double> sphere_diameter_std_mm;
  // Per sphere: how many times its fit's variances exceed what independent
  // points would give, its neighbouring points sharing their noise
  // (SphereFitUncertainty::noise_variance_inflation; in diameter_std_mm).
  std::vector<double> sphere_noise_variance_inflation;
  // Per sphere: the range of its residuals (what P_F is for the sphere).
  // Reported, not judged, for the ball bar, whose figure is SD: a patch one
  // grid period off on one ball shows here, where SD may not show it.
  std::vector<double> sphere_form_mm;
  // Plate: the outline of the face's dense part (plate_outline.h), before the
  // edge margin; the captured points not in that dense part (strays, sparse
  // edges: PlaneOutline::points_outside; some of them inside the rectangle,
  // so in the edge margin or the figures); and the captured points outside
  // the rectangle itself (part of points_off_artifact).
  double plate_outline_length_mm = 0, plate_outline_width_mm = 0;
  int plate_points_off_outline = 0;
  int plate_points_outside_rectangle = 0;
  // Plate: the points of its far face left out of F (part of
  // points_off_artifact): a second layer in the capture band whose normals
  // face the other side (a plate thinner than the band seen from both sides).
  int plate_points_far_face = 0;
  // What the figures are not, to be said with them (verify prints each as a
  // note): on a plate, two parallel layers in the band, and whether the far
  // one was left out as the plate's far face or F spans both.
  std::vector<std::string> notes;
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  double plane_offset_mm = 0;
  // Empty when the position is judged. Otherwise why it is not: a figure the
  // points or the certificate leave undetermined where the position would
  // otherwise pass (VerifyOptions::max_uncertainty_fraction_of_mpe; the text
  // names the figure, its uncertainty and what would help), or a part of
  // the artifact measured beyond the capture band, which the figures leave
  // out (the text names its points and how far off they lie). Its figures
  // are all filled in, to be reported, not judged.
  // A position not evaluated at all (NotEvaluated below) has no figures and
  // no fitted geometry; not_judged_reason then says why.
  std::string not_judged_reason;
  bool beyond_band_not_judged = false;  // not judged for a part measured beyond the capture band
  bool evaluated = true;
  bool judged() const { return not_judged_reason.empty(); }
  bool pass() const;  // judged, and every figure within its MPE
};

// A cloud that reads but is not the artifact (EvaluateArtifact below):
// verify shows it as a position not evaluated, where any other InputError
// stops the run.
class NotTheArtifactError : public InputError {
 public:
  using InputError::InputError;
};

// Throws NotTheArtifactError(`where`, ...) when the cloud has too few points on the
// artifact, the artifact cannot be found in it, what is found does not
// cover the certified artifact plausibly (a sphere or ball whose free-radius
// fit leaves the certified size or does not converge: the message names the
// ball, both diameters and the cap its points cover; a ball bar whose balls
// lie more than 10% off the certified centre distance). Points or a
// certificate that leave P_S, SD or F undetermined where the position would
// otherwise pass are no error: the evaluation comes back with every figure
// and not_judged_reason set.
//
// normals: parallel to points_mm, or empty (a cloud without nx ny nz): each
// point's normal facing the camera of the module that measured it, as a
// stereorig cloud carries (docs/formats.md). On a plate they tell a thin
// plate's far face (a second layer in the capture band measured from the
// other side: left out of F) from a module measuring the face off (measured
// from the same side: in F, which it fails); without them F spans both
// layers (ArtifactEvaluation::notes says which was found).
ArtifactEvaluation EvaluateArtifact(const Artifact& artifact, const std::vector<Eigen::Vector3d>& points_mm,
                                    const VerifyOptions& options, const std::string& where,
                                    const std::vector<Eigen::Vector3d>& normals = {});

// A position whose cloud EvaluateArtifact refused (its NotTheArtifactError's
// problem: too few points on the artifact, no artifact of the certified
// size in it): no figures, evaluated false, not_judged_reason "not
// evaluated: <reason>", so that one such cloud among several neither hides
// the others' figures nor passes (verify, several --cloud).
ArtifactEvaluation NotEvaluated(const Artifact& artifact, const VerifyOptions& options, int points_total,
                                const std::string& reason);

// Several positions of the same artifact: per figure, the judged position
// nearest to failing under the decision rule they were evaluated with (the
// largest JudgedMagnitudeMm: under simple acceptance the largest |value|),
// of the figures judged. No PASS is claimed while a position is not judged.
struct VerifySummary {
  std::vector<Figure> worst;              // one per figure name
  std::vector<int> worst_positions;       // parallel to worst: the index of its position
  std::vector<int> not_judged_positions;  // indices into the positions given
  bool pass = false;                      // every position judged, and every figure of each within its MPE
};
VerifySummary Summarise(const std::vector<ArtifactEvaluation>& positions);

namespace internal {

// A ball bar's ball 1 as evidence of a scale error for ball 2 (which ball 2
// cannot be found at, or fitted to, the certified size): ball 1's radius over
// the certified nominal_radius_mm, fitted with a free radius from
// (center_mm, radius_mm) to its points within band_mm of that sphere and
// outside the shaft's cone towards ball 2 (cos_cone: the cone's half-angle's
// cosine), as the second pass fits it; not the points of its first fit, whose
// band holds the rod's near end and reads the ball too large. NaN where that
// fit fails or does not converge, or where it overlaps ball 2 as found
// (other_center_mm, other_radius_mm): two balls cannot, so that is one ball
// found twice, and its agreeing with itself is no evidence.
double BallScaleOffShaft(const std::vector<Eigen::Vector3d>& points_mm, const Eigen::Vector3d& center_mm,
                         double radius_mm, double nominal_radius_mm, double band_mm, double cos_cone,
                         const Eigen::Vector3d& other_center_mm, double other_radius_mm);

}  // namespace internal

}  // namespace stereorig
