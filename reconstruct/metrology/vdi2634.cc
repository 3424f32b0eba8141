#include "reconstruct/metrology/vdi2634.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "calib/core/input_error.h"
#include "reconstruct/metrology/plane_fit.h"
#include "reconstruct/metrology/plate_outline.h"
#include "reconstruct/metrology/sphere_fit.h"
#include "reconstruct/metrology/sphere_uncertainty.h"
#include "reconstruct/metrology/surface_beyond_band.h"

namespace stereorig {

void VerifyOptions::Check() const {
  if (excluded_fraction_max < 0 || excluded_fraction_max > 0.05) {
    throw InputError("verify options", "excluded_fraction_max must be in [0, 0.05]");
  }
  if (min_points < 10) throw InputError("verify options", "min_points must be >= 10");
  if (ballbar_shaft_cone_deg < 0 || ballbar_shaft_cone_deg >= 90) {
    throw InputError("verify options", "ballbar_shaft_cone_deg must be in [0, 90)");
  }
  if (plate_edge_margin_mm < 0) throw InputError("verify options", "plate_edge_margin_mm must not be negative");
  if (!(capture_band_mm > 0)) throw InputError("verify options", "capture_band_mm must be positive");
  if (plate_min_coverage < 0 || plate_min_coverage > 1) {
    throw InputError("verify options", "plate_min_coverage must be in [0, 1]");
  }
  if (!(max_uncertainty_fraction_of_mpe > 0)) {
    throw InputError("verify options", "max_uncertainty_fraction_of_mpe must be positive");
  }
}

bool ArtifactEvaluation::pass() const {
  return judged() && std::all_of(figures.begin(), figures.end(), [](const Figure& f) { return f.pass; });
}

namespace {

Figure MakeFigure(const std::string& name, double value, double mpe) {
  Figure f;
  f.name = name;
  f.value_mm = value;
  f.mpe_mm = mpe;
  return f;  // pass: JudgeFigures, once its uncertainty is known
}

// The figure's standard uncertainty from its parts, either of which may be
// absent: their quadrature sum (an infinite fit part stays infinite).
void SetUncertainty(Figure* f, std::optional<double> fit_mm, std::optional<double> certificate_mm) {
  f->fit_standard_uncertainty_mm = fit_mm;
  f->certificate_standard_uncertainty_mm = certificate_mm;
  if (fit_mm || certificate_mm)
    f->standard_uncertainty_mm = std::hypot(fit_mm.value_or(0.0), certificate_mm.value_or(0.0));
}

// What the certificate certifies for a figure.
const char* CertifiedQuantity(const std::string& figure) {
  if (figure == "P_S") return "diameter";
  if (figure == "SD") return "centre distance";
  if (figure == "P_F") return "sphere's form";
  return "flatness";
}

// Why figure f is not determined: what the fit reads (the points' coverage
// and scatter), what the certificate allows, and what would help.
std::string UndeterminedText(const Figure& f, const ArtifactEvaluation& e, const std::string& coverage,
                             double coverage_factor, double limit_mm, const VerifyOptions& o) {
  const double fit_mm = f.fit_standard_uncertainty_mm.value_or(0.0);
  const double certificate_mm = f.certificate_standard_uncertainty_mm.value_or(0.0);
  char buf[320];
  std::string text = f.name + " is not determined: ";
  if (f.fit_standard_uncertainty_mm) {
    // Significant digits: beside a certificate's large part the fit's can be
    // 0.0004 mm, which %.3f printed as "+-0.000".
    std::snprintf(buf, sizeof buf, "%s and scatter by %.3f mm (residual std)", coverage.c_str(), e.residual_std_mm);
    text += buf;
    // Noise that neighbouring points share fits the shape worse than as many
    // independent points: by how much (SphereFitUncertainty).
    const auto& inflation = e.sphere_noise_variance_inflation;
    if (const double most = inflation.empty() ? 1.0 : *std::max_element(inflation.begin(), inflation.end()); most > 1) {
      std::snprintf(buf, sizeof buf, ", shared by neighbouring points (u x%.1f)", std::sqrt(most));
      text += buf;
    }
    std::snprintf(buf, sizeof buf, ", which fits it to +-%.3g mm (1 sigma)", fit_mm);
    text += buf;
  }
  if (certificate_mm > 0) {
    std::snprintf(buf, sizeof buf, "%sthe certificate gives the %s to +-%.3f mm (1 sigma: U %.3f mm at k = %g)",
                  f.fit_standard_uncertainty_mm ? ", and " : "", CertifiedQuantity(f.name), certificate_mm,
                  certificate_mm * coverage_factor, coverage_factor);
    text += buf;
    if (f.fit_standard_uncertainty_mm) {
      std::snprintf(buf, sizeof buf, ": +-%.3f mm combined", *f.standard_uncertainty_mm);
      text += buf;
    }
  }
  std::snprintf(buf, sizeof buf, ", more than %.0f%% of its MPE (%.3f mm); ", 100 * o.max_uncertainty_fraction_of_mpe,
                f.mpe_mm);
  text += buf;
  // At the limit exactly, any fit part puts u over it: U must stay under.
  if (certificate_mm >= limit_mm) {
    std::snprintf(
        buf, sizeof buf,
        "the certificate's part alone is at or over it: verify needs an artifact calibrated to U < %.3f mm (k = %g)",
        limit_mm * coverage_factor, coverage_factor);
  } else if (certificate_mm > 0 && std::isfinite(fit_mm) && fit_mm > 0 && fit_mm <= limit_mm) {
    std::snprintf(buf, sizeof buf,
                  "measure more of the artifact, or with less noise: with this certificate the fit must reach "
                  "+-%.3f mm",
                  std::sqrt(limit_mm * limit_mm - certificate_mm * certificate_mm));
  } else {
    std::snprintf(buf, sizeof buf, "measure more of the artifact, or with less noise");
  }
  return text + buf;
}

// Whether figure f is determined enough to judge: no uncertainty at all (a
// range of residuals against an exact reference), or a combined u within
// VerifyOptions::max_uncertainty_fraction_of_mpe of its MPE. A non-finite or
// non-positive fit part counts as undetermined (a certificate's 0 is an
// exact reference).
bool Determined(const Figure& f, const VerifyOptions& o) {
  if (!f.standard_uncertainty_mm) return true;
  const bool fit_determined = !f.fit_standard_uncertainty_mm || *f.fit_standard_uncertainty_mm > 0;
  return fit_determined && *f.standard_uncertainty_mm <= o.max_uncertainty_fraction_of_mpe * f.mpe_mm;
}

// Whether figure f's stated u is a floor, not its error: its fit's part is
// itself undetermined (over the limit, or non-finite or non-positive: a cap
// too small to fit a diameter, whose covariance counts its points as
// independent and its misfit as noise). A certificate's part is not: U is the
// calibration's stated expanded uncertainty, and a fit's part within the
// limit stands as a determined figure's does. A figure undetermined only by
// its certificate (its fit within the limit, or no fit part: P_F, F) has a u
// to judge with, too large to pass on.
bool UncertaintyIsAFloor(const Figure& f, const VerifyOptions& o) {
  if (!f.fit_standard_uncertainty_mm) return false;
  const double fit_mm = *f.fit_standard_uncertainty_mm;
  return !(fit_mm > 0 && fit_mm <= o.max_uncertainty_fraction_of_mpe * f.mpe_mm);
}

// Whether an undetermined figure's FAIL stands all the same. Simple
// acceptance reads the value alone, so its failure stands where the value
// itself is beyond doubt: beyond the MPE by more than its stated 2u (the
// nonconformance zone: more than its noise). Under guarded acceptance any
// failure stands (a larger u only widens the guard band). Under guarded
// rejection a failure is already in the nonconformance zone: it stands where
// u is the figure's (a certificate's U that dominates it), not where u is a
// floor (UncertaintyIsAFloor: a larger u could pull the value out of that
// zone).
bool FailureStands(DecisionRule rule, const Figure& f) {
  if (f.pass) return false;
  switch (rule) {
    case DecisionRule::kSimpleAcceptance:
      return f.zone() == ConformanceZone::kNonconformance;
    case DecisionRule::kGuardedAcceptance:
      return true;
    case DecisionRule::kGuardedRejection:
      return !f.uncertainty_is_floor && f.zone() == ConformanceZone::kNonconformance;
  }
  return false;
}

// Each figure's pass under the rule, from its value and its U (set above),
// and whether that verdict stands (Figure::judged): the figure is
// determined, or its failure stands without it.
void JudgeFigures(DecisionRule rule, const VerifyOptions& o, std::vector<Figure>* figures) {
  for (Figure& f : *figures) {
    f.pass = Passes(rule, f.value_mm, f.ExpandedUncertaintyMm(), f.mpe_mm);
    const bool determined = Determined(f, o);
    f.uncertainty_is_floor = !determined && UncertaintyIsAFloor(f, o);
    f.judged = determined || FailureStands(rule, f);
  }
}

// Why a position whose verdict would rest on a figure the fit or the
// certificate leaves undetermined (Figure::judged false: its value would be
// the fit's noise, or its reference not known well enough) is not judged:
// neither a PASS nor a FAIL can be claimed from it. Empty when every figure
// is judged, or one that is judged fails: the position is judged, FAIL,
// whatever the others leave undetermined.
std::string NotJudgedReason(const ArtifactEvaluation& e, const std::string& coverage, double coverage_factor,
                            const VerifyOptions& o) {
  for (const Figure& f : e.figures)
    if (f.judged && !f.pass) return "";
  for (const Figure& f : e.figures) {
    if (f.judged) continue;
    return UndeterminedText(f, e, coverage, coverage_factor, o.max_uncertainty_fraction_of_mpe * f.mpe_mm, o);
  }
  return "";
}

// A part of the artifact measured beyond the capture band (`what`: "the
// sphere's surface", "ball 2's surface", "the plate's face";
// surface_beyond_band.h) is left out of the figures, so
// they cannot show it: a position that would pass is not judged (a larger
// gross error must not pass where a smaller one fails), one that fails
// keeps its FAIL with the part named in a note.
void JudgeSurfaceBeyondBand(const SurfaceBeyondBand& s, const std::string& what, double band_mm,
                            ArtifactEvaluation* e) {
  if (!s.found()) return;
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%d points lie %.1f to %.1f mm off %s, beyond the %.1f mm capture band, where the band holds "
                "none of it (or another module's points there) but all around holds it: a part of it measured that far "
                "off (a patch a grid period or "
                "more off?), which the figures leave out. Crop it from the cloud if it is something else, or give "
                "--capture-band-mm %.0f to judge it",
                s.points, s.nearest_mm, s.farthest_mm, what.c_str(), band_mm, std::ceil(s.farthest_mm + 1));
  if (e->pass()) {
    e->not_judged_reason = buf;
    e->beyond_band_not_judged = true;
  } else {
    e->notes.push_back(buf);
  }
}

// On the plate a layer where the face is missing is either the face measured
// off or an object on it whose sides were not captured (a clamp's top 8 mm
// above the face): where it lies tells them apart only on one side. An
// object on the face lies on the side the face was measured from (behind
// it the plate would hide it), so a layer there is left out with a note;
// behind the face, or where the side is unknown (a cloud without normals),
// nothing but the face measured off can lie, and the plate is not passed.
// Each part is placed on its own: a clamp in front does not vouch for a
// patch behind (one mean over both called all of them in front, PASS).
// Widening the band is no way to judge an object: it would put it in F.
void JudgePlateFaceBeyondBand(const SurfaceBeyondBand& s, int face_side, double band_mm, ArtifactEvaluation* e) {
  if (!s.found()) return;
  const bool on_measured_side = face_side != 0 && std::all_of(s.part_mean_off_mm.begin(), s.part_mean_off_mm.end(),
                                                              [&](double off_mm) { return off_mm * face_side > 0; });
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%d points lie %.1f to %.1f mm %s the plate's face, beyond the %.1f mm capture band, where the band "
                "holds none of the face but all around holds it: %s, which the figures leave out. Crop it away if "
                "it is not the plate; if it is the plate's surface measured off, the rig measured it wrongly "
                "(--capture-band-mm %.0f shows its figure)",
                s.points, s.nearest_mm, s.farthest_mm, on_measured_side ? "in front of" : "off", band_mm,
                on_measured_side ? "an object on the face (a clamp?) whose sides were not captured, or a part of the "
                                   "face measured that far off"
                                 : "a part of the face measured that far off (a patch a grid period or more off?)",
                std::ceil(s.farthest_mm + 1));
  if (e->pass() && !on_measured_side) {
    e->not_judged_reason = buf;
    e->beyond_band_not_judged = true;
  } else {
    e->notes.push_back(buf);
  }
}

std::string CapsText(const std::vector<double>& cap_half_angles_deg) {
  std::string text =
      cap_half_angles_deg.size() == 1 ? "the sphere's points cover a cap of " : "the balls' points cover caps of ";
  for (size_t k = 0; k < cap_half_angles_deg.size(); ++k) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.0f", k ? " and " : "", cap_half_angles_deg[k]);
    text += buf;
  }
  return text + " deg half-angle";
}

// Drops the largest-|residual| points, at most `fraction` of them, and
// returns the kept indices.
std::vector<int> ExcludeWorst(const std::vector<int>& indices, const std::vector<double>& residuals, double fraction,
                              int* excluded) {
  const int n = static_cast<int>(indices.size());
  *excluded = static_cast<int>(std::floor(fraction * n));
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(residuals[a]) < std::abs(residuals[b]); });
  std::vector<int> kept;
  for (int k = 0; k < n - *excluded; ++k) kept.push_back(indices[order[k]]);
  std::sort(kept.begin(), kept.end());
  return kept;
}

void ResidualStats(const std::vector<double>& r, ArtifactEvaluation* e) {
  double sa = 0, s = 0, ss = 0;
  for (double x : r) {
    sa += std::abs(x);
    s += x;
    ss += x * x;
  }
  const double n = static_cast<double>(r.size());
  e->residual_mean_abs_mm = sa / n;
  e->residual_std_mm = std::sqrt(std::max(0.0, ss / n - (s / n) * (s / n)));
}

double Range(const std::vector<double>& r) {
  const auto [lo, hi] = std::minmax_element(r.begin(), r.end());
  return *hi - *lo;
}

// Segmentation rounds: a point set and its fit are iterated until the set
// no longer changes (2-4 rounds in practice).
constexpr int kMaxSegmentationRounds = 20;

// Gauss-Newton iterations of a sphere fit (it converges in 3-6 from a start
// near the solution: sphere_fit.h).
constexpr int kRefineIterations = 50;

std::string Mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// RANSAC's band, which only locates the shape.
double LocateBandMm(const VerifyOptions& o, double mpe_mm) { return o.locate_band_mm > 0 ? o.locate_band_mm : mpe_mm; }

// A sphere's or ball's locating band: the figure's MPE (LocateBandMm), but
// never more than an eighth of the certified radius. The band locates the
// sphere, widens RANSAC's radius tolerance (RadiusToleranceMm) and scales the
// check that the points lie on a sphere (a quarter of it), so an MPE of the
// sphere's own size made them all vacuous: with P_F 50 mm a cup 84 mm across
// was judged as the 38.1 mm sphere, and passed. An eighth lets the band widen
// the 10% tolerance to 12.5% at most, and holds the demo ball bar's default
// 1.5 mm on its 12.7 mm balls (11.8%); the sphere's 1.5 mm is under its
// 2.4 mm. The capture band is not capped: it still takes every point within
// twice the MPE, as the figures must see an error up to it.
constexpr double kMaxLocateBandOfRadius = 0.125;

double SphereLocateBandMm(const VerifyOptions& o, double mpe_mm, double nominal_radius_mm) {
  return std::min(LocateBandMm(o, mpe_mm), kMaxLocateBandOfRadius * nominal_radius_mm);
}

// The band whose points are the artifact's: never so narrow that an error
// beyond the MPE is cut off before the figures see it.
double CaptureBandMm(const VerifyOptions& o, double mpe_mm) { return std::max(o.capture_band_mm, 2 * mpe_mm); }

// The MPE the band must not cut an error of: the artifact type's figures'.
double BandMpeMm(const Artifact& a) {
  switch (a.type) {
    case ArtifactType::kSphere:
      return std::max(a.mpe.probing_form_mm, a.mpe.probing_size_mm);
    case ArtifactType::kBallBar:
      return a.mpe.sphere_spacing_mm;
    case ArtifactType::kPlate:
      return a.mpe.flatness_mm;
  }
  return 0;
}

std::vector<int> WithinSphereShell(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& center_mm,
                                   double radius_mm, double band_mm) {
  std::vector<int> in;
  for (int i = 0; i < static_cast<int>(pts.size()); ++i)
    if (std::abs((pts[i] - center_mm).norm() - radius_mm) < band_mm) in.push_back(i);
  return in;
}

// A sphere evaluated where it is: its residuals over `indices` (no fit).
SphereFit SphereAt(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& indices,
                   const Eigen::Vector3d& center_mm, double radius_mm) {
  SphereFit at;
  at.ok = true;
  at.center_mm = center_mm;
  at.radius_mm = radius_mm;
  at.inliers = indices;
  for (int i : indices) at.residuals_mm.push_back((pts[i] - center_mm).norm() - radius_mm);
  return at;
}

// One sphere of the certified size, located and fitted: `located` false when
// RANSAC found none (fit.message says why); otherwise fit.ok false when the
// free-radius fit of the located sphere's points left the certified size or
// did not converge (fit.message says what it saw).
struct ArtifactSphereFit {
  bool located = false;
  Eigen::Vector3d located_center_mm = Eigen::Vector3d::Zero();  // of the sphere of the certified size
  SphereFit fit;
  int excluded = 0;
};

// How far a free fit's radius may leave the certified one: RANSAC's own
// tolerance for a sphere of the certified size.
double RadiusToleranceMm(double locate_band_mm, double nominal_radius_mm) {
  return std::max(locate_band_mm, 0.1 * nominal_radius_mm);
}

bool LeftCertifiedSize(const SphereFit& fit, double nominal_radius_mm, double tolerance_mm) {
  return !fit.ok || !fit.converged || !(std::abs(fit.radius_mm - nominal_radius_mm) <= tolerance_mm);
}

double SumOfSquares(const std::vector<double>& r) {
  double ss = 0;
  for (double x : r) ss += x * x;
  return ss;
}

// ", or measured at a scale +20% off (...)": a sphere's fitted size is a fact
// about the cloud, and a rig calibrated with a wrong target square size reads
// every length scaled. Said only where that is plausible: within 50% of the
// certified size, and on a ball bar only if the other ball (its fitted
// radius over the certified, when known) is off the same way, by at least
// half as much.
std::string ScaleText(double scale, std::optional<double> other_ball_scale) {
  const double off = scale - 1;
  if (!(std::abs(off) <= 0.5)) return "";
  if (other_ball_scale &&
      !((*other_ball_scale - 1) * off > 0 && std::abs(*other_ball_scale - 1) >= 0.5 * std::abs(off)))
    return "";
  char buf[160];
  std::snprintf(buf, sizeof buf,
                ", or measured at a scale %+.0f%% off (a rig calibrated with a wrong target square size reads every "
                "length so)",
                100 * off);
  return buf;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The median |radial residual|, mm, of the points within band_mm of a
// sphere: how well they lie on it. The artifact at another scale lies on its
// fitted sphere to the measurement's noise (0.05 mm on the demo's); a ball
// with its rod, or a patch of a plane, fitted as one sphere does not (a
// walkthrough's ball bar read "-10% off" against a sphere file, a plate
// "+16% off").
double MedianAbsResidualMm(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& center_mm, double radius_mm,
                           double band_mm) {
  std::vector<double> r;
  for (int i : WithinSphereShell(pts, center_mm, radius_mm, band_mm))
    r.push_back(std::abs((pts[i] - center_mm).norm() - radius_mm));
  return r.empty() ? std::numeric_limits<double>::infinity() : Median(r);
}

// "; most of the cloud (N of M points) lies within 1.5 mm of a plane: a
// plate?" where RANSAC's plane holds over half of it; empty otherwise.
std::string PlaneLikeText(const std::vector<Eigen::Vector3d>& pts, double locate_band_mm) {
  PlaneFitOptions po;
  po.inlier_threshold_mm = locate_band_mm;
  const PlaneFit plane = FitPlaneRobust(pts, po);
  if (!plane.ok || 2 * plane.inliers.size() <= pts.size()) return "";
  char buf[160];
  std::snprintf(buf, sizeof buf, "; most of the cloud (%zu of %zu points) lies within %.1f mm of a plane: a plate?",
                plane.inliers.size(), pts.size(), locate_band_mm);
  return buf;
}

// ScaleText for a sphere found at another size (centre, radius), named only
// where its points within band_mm lie on it to within a quarter of the
// locating band (MedianAbsResidualMm): the artifact at another scale does,
// to its noise. Otherwise the cloud is said not to look like the artifact,
// and what it looks like where that is cheap to tell (PlaneLikeText).
std::string ScaleOrShapeText(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& center_mm,
                             double radius_mm, double nominal_radius_mm, double band_mm, double locate_band_mm,
                             std::optional<double> other_ball_scale) {
  const std::string scale = ScaleText(radius_mm / nominal_radius_mm, other_ball_scale);
  if (scale.empty()) return "";
  const double median_mm = MedianAbsResidualMm(pts, center_mm, radius_mm, band_mm);
  if (median_mm <= 0.25 * locate_band_mm) return scale;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "; its points lie on that sphere only to %.2f mm (median |residual|; the artifact at another scale "
                "would to its noise, under a quarter of the %.1f mm locating band): the cloud does not look like "
                "this artifact",
                median_mm, locate_band_mm);
  return buf + PlaneLikeText(pts, locate_band_mm);
}

// Why a located sphere's free-radius fit is not the artifact's: the cap its
// points cover, the diameter they fit against the certified one, and how well
// a cap like this fits a diameter at all, so the reader can tell a cap too
// small to fit from another object. That last is the fit's covariance taken at
// the located sphere of the certified size (a runaway fit's own is
// meaningless), with the noise of the better-fitting of the two spheres.
std::string LeftCertifiedSizeText(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& captured,
                                  const Eigen::Vector3d& located_center_mm, const SphereFit& free_fit,
                                  double nominal_radius_mm, double tolerance_mm, double capture_band_mm,
                                  double locate_band_mm, std::optional<double> other_ball_scale) {
  SphereFitUncertainty u{180.0, std::numeric_limits<double>::infinity(), {}};
  if (captured.size() > 4) {
    SphereFit at = SphereAt(pts, captured, located_center_mm, nominal_radius_mm);
    if (free_fit.ok && free_fit.residuals_mm.size() == captured.size() &&
        SumOfSquares(free_fit.residuals_mm) < SumOfSquares(at.residuals_mm)) {
      at.residuals_mm = free_fit.residuals_mm;
    }
    u = SphereUncertainty(pts, at);
  }
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "its %zu points within %.1f mm of the sphere of the certified size cover a cap of %.0f deg half-angle and ",
      captured.size(), capture_band_mm, u.cap_half_angle_deg);
  std::string text = buf;
  if (!free_fit.ok) {
    text += "a free-radius fit of them failed (" + free_fit.message + ")";
  } else if (!free_fit.converged) {
    std::snprintf(buf, sizeof buf,
                  "a free-radius fit of them did not converge in %d iterations (last at %.1f mm in diameter; the "
                  "certified is %.1f mm)",
                  kRefineIterations, 2 * free_fit.radius_mm, 2 * nominal_radius_mm);
    text += buf;
  } else {
    std::snprintf(
        buf, sizeof buf,
        "fit, with a free radius, a sphere %.1f mm in diameter, not the certified %.1f mm (+-%.1f mm allowed)",
        2 * free_fit.radius_mm, 2 * nominal_radius_mm, 2 * tolerance_mm);
    text += buf;
  }
  // First whether the points lie on a sphere at all (the better of the
  // free fit and the located one, to within a quarter of the locating band
  // as the artifact does to its noise on any cap): points that do not are
  // not the artifact, however much of it they cover, and u from their
  // misfit is no measure of the cap (the demo's ball bar against its
  // sphere's file covered 63 deg and read "a cap this small fits a diameter
  // only to +-1.94 mm: measure more of it").
  const bool free_fitted = free_fit.ok && free_fit.converged;
  auto median_abs_residual_mm = [&](const Eigen::Vector3d& center_mm, double radius_mm) {
    std::vector<double> r;
    for (int i : captured) r.push_back(std::abs((pts[i] - center_mm).norm() - radius_mm));
    return r.empty() ? std::numeric_limits<double>::infinity() : Median(r);
  };
  const double median_mm = std::min(free_fitted ? median_abs_residual_mm(free_fit.center_mm, free_fit.radius_mm)
                                                : std::numeric_limits<double>::infinity(),
                                    median_abs_residual_mm(located_center_mm, nominal_radius_mm));
  if (!(median_mm <= 0.25 * locate_band_mm)) {
    std::snprintf(buf, sizeof buf,
                  "; its points lie on no sphere better than %.2f mm (median |residual|; the artifact would to its "
                  "noise, under a quarter of the %.1f mm locating band, on a cap of any size): the cloud does not "
                  "look like this artifact",
                  median_mm, locate_band_mm);
    return text + buf + PlaneLikeText(pts, locate_band_mm);
  }
  // A cap that cannot pin the diameter within the tolerance (3 sigma) is too
  // small; one that can, and fits another size, is another object.
  if (!(3 * u.diameter_std_mm <= 2 * tolerance_mm)) {
    std::snprintf(buf, sizeof buf, "; a cap this small fits a diameter only to +-%.2f mm (1 sigma): measure more of it",
                  u.diameter_std_mm);
  } else {
    std::snprintf(buf, sizeof buf,
                  "; a cap like this fits a diameter to +-%.4f mm (1 sigma): not the artifact, or not of its certified "
                  "size",
                  u.diameter_std_mm);
    text += buf;
    if (free_fitted) {
      text += ScaleOrShapeText(pts, free_fit.center_mm, free_fit.radius_mm, nominal_radius_mm, capture_band_mm,
                               locate_band_mm, other_ball_scale);
    }
    return text;
  }
  return text + buf;
}

// On a ball bar's second ball: the first ball's fitted radius over the
// certified one, measured as the second pass measures it once this ball's
// sphere as found (its centre and radius, mm) gives the bar's axis
// (internal::BallScaleOffShaft): NaN where that fit fails or overlaps this
// ball. Empty for a sphere, or a ball bar's first ball (no other ball yet).
using OtherBallScaleAt = std::function<double(const Eigen::Vector3d& center_mm, double radius_mm)>;

// A ball's points: those within the capture band of its sphere and outside
// the shaft's cone about the bar axis (towards the other ball's centre).
std::vector<int> BallPointsOffShaft(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& center_mm,
                                    double radius_mm, double band_mm, const Eigen::Vector3d& other_center_mm,
                                    double cos_cone) {
  const Eigen::Vector3d axis = (other_center_mm - center_mm).normalized();
  std::vector<int> in;
  for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
    const Eigen::Vector3d d = pts[i] - center_mm;
    if (std::abs(d.norm() - radius_mm) >= band_mm || d.norm() < 1e-9 || d.normalized().dot(axis) > cos_cone) continue;
    in.push_back(i);
  }
  return in;
}

}  // namespace

namespace internal {

double BallScaleOffShaft(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& center_mm, double radius_mm,
                         double nominal_radius_mm, double band_mm, double cos_cone,
                         const Eigen::Vector3d& other_center_mm, double other_radius_mm) {
  const std::vector<int> own = BallPointsOffShaft(pts, center_mm, radius_mm, band_mm, other_center_mm, cos_cone);
  const SphereFit f = RefineSphere(pts, own, center_mm, radius_mm, kRefineIterations);
  if (!f.ok || !f.converged) return std::numeric_limits<double>::quiet_NaN();
  // Two balls cannot overlap: where they do, they are one ball found twice.
  if ((f.center_mm - other_center_mm).norm() < std::abs(f.radius_mm) + std::abs(other_radius_mm))
    return std::numeric_limits<double>::quiet_NaN();
  return f.radius_mm / nominal_radius_mm;
}

}  // namespace internal

namespace {

// When no sphere of the certified size is found: whether the cloud holds a
// sphere of another size (RANSAC with the radius free, within half to twice
// the certified one, at least min_points points within the band), and the
// scale that would make it the artifact's; empty if it holds none. On a
// ball bar's first ball (first_of_ball_bar) the scale is named only if the
// cloud holds a second sphere off the same way (ScaleText): a single sphere
// given for a ball bar is the wrong artifact file, not a scale (it read
// "+50% off", a user's walkthrough found). On its second ball, only if the
// first, measured without the rod towards the sphere found
// (other_ball_scale_at), is off the same way.
std::string OtherSizeText(const std::vector<Eigen::Vector3d>& pts, double nominal_radius_mm, double locate_band_mm,
                          const OtherBallScaleAt& other_ball_scale_at, const VerifyOptions& o,
                          bool first_of_ball_bar = false) {
  SphereFitOptions so;
  so.inlier_threshold_mm = locate_band_mm;
  so.expected_radius_mm = 1.25 * nominal_radius_mm;  // hypotheses in [0.5, 2] x the certified radius
  so.radius_tolerance_mm = 0.75 * nominal_radius_mm;
  so.ransac_iterations = 1000;
  so.seed = o.seed;
  auto plausible = [&](const SphereFit& f) {
    return f.ok && f.converged && static_cast<int>(f.inliers.size()) >= o.min_points &&
           f.radius_mm >= 0.5 * nominal_radius_mm && f.radius_mm <= 2 * nominal_radius_mm;
  };
  const SphereFit other = FitSphereRobust(pts, so);
  if (!plausible(other)) return "";
  std::optional<double> other_ball_scale;
  if (other_ball_scale_at) other_ball_scale = other_ball_scale_at(other.center_mm, other.radius_mm);
  if (first_of_ball_bar) {
    other_ball_scale = std::numeric_limits<double>::quiet_NaN();  // no second sphere: no scale named
    std::vector<Eigen::Vector3d> rest;
    for (const auto& p : pts)
      if ((p - other.center_mm).norm() > other.radius_mm + locate_band_mm) rest.push_back(p);
    if (const SphereFit second = FitSphereRobust(rest, so); plausible(second))
      other_ball_scale = second.radius_mm / nominal_radius_mm;
  }
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "; it holds one %.1f mm in diameter (%zu points within %.1f mm of it), not the certified %.1f mm: not "
                "the artifact, or not of its certified size",
                2 * other.radius_mm, other.inliers.size(), locate_band_mm, 2 * nominal_radius_mm);
  return buf + ScaleOrShapeText(pts, other.center_mm, other.radius_mm, nominal_radius_mm, locate_band_mm,
                                locate_band_mm, other_ball_scale);
}

// "ball 2 of the ball bar (centre near (50.0, 0.0, 150.0) mm)": which one
// is RANSAC's order, so the centre says where it is.
std::string BallText(int ball, const Eigen::Vector3d& center_mm) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "ball %d of the ball bar (centre near (%.1f, %.1f, %.1f) mm)", ball + 1, center_mm.x(),
                center_mm.y(), center_mm.z());
  return buf;
}

// One sphere of known nominal radius: locate (RANSAC with the certified size,
// its centre refined with the radius held, on whichever side of the points
// fits better: sphere_fit.h; a free radius refined straight from a 4-point
// hypothesis on the wrong side of a small cap must pass through a plane to
// reach the right side, and ran away to spheres kilometres wide), capture
// (every point within the capture band, iterated with the free-radius fit to
// a fixed point), exclude, refit. The radius is free in every fit after
// locating: P_S and SD are measured, not assumed; a free fit that leaves the
// certified size (RANSAC's own tolerance) or does not converge is reported
// as such.
// other_ball_scale_at: on a ball bar's second ball, the first's size
// (OtherBallScaleAt, for ScaleText); first_of_ball_bar: the ball bar's
// first ball, whose other is not known yet.
ArtifactSphereFit FitArtifactSphere(const std::vector<Eigen::Vector3d>& pts, double nominal_radius,
                                    double locate_band_mm, double capture_band_mm, const VerifyOptions& o,
                                    const OtherBallScaleAt& other_ball_scale_at = {}, bool first_of_ball_bar = false) {
  SphereFitOptions so;
  so.inlier_threshold_mm = locate_band_mm;
  so.expected_radius_mm = nominal_radius;
  so.radius_tolerance_mm = RadiusToleranceMm(locate_band_mm, nominal_radius);
  so.ransac_iterations = 1000;
  so.seed = o.seed;
  so.refine_radius = false;
  ArtifactSphereFit out;
  const SphereFit located = FitSphereRobust(pts, so);
  if (!located.ok) {
    out.fit = located;
    out.fit.message += OtherSizeText(pts, nominal_radius, locate_band_mm, other_ball_scale_at, o, first_of_ball_bar);
    return out;
  }
  // Found at the certified size, a ball bar's first ball that then leaves it
  // names no scale: the other ball, which would have to be off the same way,
  // is not fitted yet. Asked only where this ball's free fit leaves the
  // size, the one place the answer is used.
  auto other_ball_scale = [&]() -> std::optional<double> {
    if (first_of_ball_bar) return std::numeric_limits<double>::quiet_NaN();
    if (other_ball_scale_at) return other_ball_scale_at(located.center_mm, located.radius_mm);
    return std::nullopt;
  };
  out.located = true;
  out.located_center_mm = located.center_mm;
  // The artifact's points are those within the capture band of the fitted
  // sphere: iterate to that fixed point, so the set does not depend on
  // RANSAC's path. The located sphere has the certified radius, so the set is
  // refitted with a free radius at least once (the exclusion ranks the free
  // fit's residuals). Each free fit must stay the certified size, within
  // RANSAC's own tolerance: on a cloud of something else, or on a cap too
  // small to fit a diameter, it leaves it.
  SphereFit fit = located;
  std::vector<int> in = WithinSphereShell(pts, located.center_mm, located.radius_mm, capture_band_mm);
  for (int it = 0; it < kMaxSegmentationRounds; ++it) {
    fit = RefineSphere(pts, in, fit.center_mm, fit.radius_mm, kRefineIterations);
    if (LeftCertifiedSize(fit, nominal_radius, so.radius_tolerance_mm)) {
      out.fit.ok = false;
      out.fit.message = LeftCertifiedSizeText(pts, in, located.center_mm, fit, nominal_radius, so.radius_tolerance_mm,
                                              capture_band_mm, locate_band_mm, other_ball_scale());
      return out;
    }
    std::vector<int> next = WithinSphereShell(pts, fit.center_mm, fit.radius_mm, capture_band_mm);
    if (next == in) break;
    in.swap(next);
  }
  const std::vector<int> kept = ExcludeWorst(fit.inliers, fit.residuals_mm, o.excluded_fraction_max, &out.excluded);
  out.fit = RefineSphere(pts, kept, fit.center_mm, fit.radius_mm, kRefineIterations);
  if (LeftCertifiedSize(out.fit, nominal_radius, so.radius_tolerance_mm)) {
    out.fit.message =
        LeftCertifiedSizeText(pts, kept, located.center_mm, out.fit, nominal_radius, so.radius_tolerance_mm,
                              capture_band_mm, locate_band_mm, other_ball_scale());
    out.fit.ok = false;
  }
  return out;
}

std::vector<int> WithinPlaneBand(const std::vector<Eigen::Vector3d>& pts, const PlaneFit& plane, double band_mm) {
  std::vector<int> in;
  for (int i = 0; i < static_cast<int>(pts.size()); ++i)
    if (std::abs(plane.normal.dot(pts[i]) - plane.offset_mm) < band_mm) in.push_back(i);
  return in;
}

// Where the face's points (inside the eroded outline) lie in two layers
// parallel to the fitted plane `plane`: their distances along its normal fall
// in two clusters (1-D two-means) apart by more than kFacesApartInSpreads
// times their pooled spread, and the smaller one's dense part spans at least
// VerifyOptions::plate_min_coverage of the plate as the face must. The
// plate's far face, seen by modules on its other side, lies in the capture
// band when the plate is thinner than the band (the walkthrough's 3 mm plate
// read F 3.47 mm, its thickness); so does the face as a miscalibrated module
// measures it, that far off, which F must fail. Positions alone cannot tell
// them apart; the points' normals can (LayersFacing). A patch one grid period
// off is a patch, not a layer: it spans too little, and F shows it. One face
// splits into halves only 2.7 spreads apart (noise), a bowed one ~3.5
// (uniform).
constexpr double kFacesApartInSpreads = 8;

struct TwoLayers {
  bool found = false;
  double apart_mm = 0;
  std::vector<int> larger, smaller;  // indices into the points, ascending as `face` is
  PlaneOutline smaller_outline;
};

TwoLayers FindTwoLayers(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& face, const PlaneFit& plane,
                        const Artifact& a, const VerifyOptions& o) {
  std::vector<double> d_mm;
  for (int i : face) d_mm.push_back(plane.normal.dot(pts[i]) - plane.offset_mm);
  if (d_mm.empty()) return {};
  double split_mm = std::accumulate(d_mm.begin(), d_mm.end(), 0.0) / d_mm.size();
  double mean_mm[2] = {0, 0}, ss_mm2[2] = {0, 0};
  size_t n[2] = {0, 0};
  for (int round = 0; round < kMaxSegmentationRounds; ++round) {
    double sum_mm[2] = {0, 0};
    n[0] = n[1] = 0;
    for (double d : d_mm) {
      sum_mm[d >= split_mm] += d;
      ++n[d >= split_mm];
    }
    if (n[0] == 0 || n[1] == 0) return {};
    mean_mm[0] = sum_mm[0] / n[0];
    mean_mm[1] = sum_mm[1] / n[1];
    const double next_mm = 0.5 * (mean_mm[0] + mean_mm[1]);
    if (next_mm == split_mm) break;
    split_mm = next_mm;
  }
  for (double d : d_mm) {
    const int k = d >= split_mm;
    ss_mm2[k] += (d - mean_mm[k]) * (d - mean_mm[k]);
  }
  const double spread_mm = std::sqrt((ss_mm2[0] + ss_mm2[1]) / d_mm.size());
  TwoLayers two;
  two.apart_mm = mean_mm[1] - mean_mm[0];
  if (!(two.apart_mm > kFacesApartInSpreads * spread_mm)) return {};
  const int smaller = n[1] < n[0] ? 1 : 0;
  for (size_t k = 0; k < face.size(); ++k)
    ((d_mm[k] >= split_mm) == (smaller == 1) ? two.smaller : two.larger).push_back(face[k]);
  if (static_cast<int>(two.smaller.size()) < std::max(o.min_points, 3)) return {};
  two.smaller_outline = OutlineOfDensePart(pts, two.smaller, plane.normal);
  const double longer = std::max(a.plate_length_mm, a.plate_width_mm);
  const double shorter = std::min(a.plate_length_mm, a.plate_width_mm);
  if (two.smaller_outline.length_mm() < o.plate_min_coverage * longer ||
      two.smaller_outline.width_mm() < o.plate_min_coverage * shorter)
    return {};
  two.found = true;
  return two;
}

// Which side of the plane a layer's points were measured from: the mean of
// their unit normals (a stereorig cloud's face the measuring module's camera,
// docs/formats.md) along the plane's normal, +1 or -1; 0 where the points
// carry no normals or their mean lies within 60 degrees of the plane (no side
// stands out).
int SideMeasuredFrom(const std::vector<Eigen::Vector3d>& normals, const std::vector<int>& layer,
                     const Eigen::Vector3d& plane_normal) {
  if (normals.empty()) return 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (int i : layer) {
    if (normals[i].norm() == 0) continue;  // written as no direction
    sum += normals[i].normalized();
    ++n;
  }
  if (n == 0) return 0;
  const double along = plane_normal.dot(sum / n);
  return along >= 0.5 ? 1 : along <= -0.5 ? -1 : 0;
}

enum class LayersFacing { kUnknown, kOppositeSides, kSameSide };

LayersFacing FacingOf(const std::vector<Eigen::Vector3d>& normals, const TwoLayers& two,
                      const Eigen::Vector3d& plane_normal) {
  const int larger = SideMeasuredFrom(normals, two.larger, plane_normal);
  const int smaller = SideMeasuredFrom(normals, two.smaller, plane_normal);
  if (larger == 0 || smaller == 0) return LayersFacing::kUnknown;
  return larger == smaller ? LayersFacing::kSameSide : LayersFacing::kOppositeSides;
}

// The note for two layers: the far face left out of F, or F judged over both
// (a module that far off; or, the points not saying which side they were
// measured from, either).
std::string TwoLayersNote(const TwoLayers& two, LayersFacing facing, bool has_normals, double capture_band_mm) {
  char buf[640];
  switch (facing) {
    case LayersFacing::kOppositeSides:
      std::snprintf(buf, sizeof buf,
                    "the plate's far face, %.1f mm behind the face (%zu points, measured from its other side: their "
                    "normals face away from the face's), left out of F and counted in off",
                    two.apart_mm, two.smaller.size());
      break;
    case LayersFacing::kSameSide:
      std::snprintf(buf, sizeof buf,
                    "F's points form two parallel layers %.1f mm apart (%zu points on the smaller), both measured "
                    "from the same side (their normals face the same way): not the plate's far face; a module "
                    "measuring the face %.1f mm off?",
                    two.apart_mm, two.smaller.size(), two.apart_mm);
      break;
    case LayersFacing::kUnknown:
      std::snprintf(buf, sizeof buf,
                    "F's points form two parallel layers %.1f mm apart (%zu points on the smaller): a plate thinner "
                    "than the %.1f mm capture band seen from both sides (its far face), or a module measuring the "
                    "face %.1f mm off; %s, so F spans both. A stereorig cloud (reconstruct --out: nx ny nz per "
                    "point) lets verify tell them apart and leave a far face out",
                    two.apart_mm, two.smaller.size(), capture_band_mm, two.apart_mm,
                    has_normals ? "their normals face no side clearly" : "the cloud has no normals to tell which");
      break;
  }
  return buf;
}

// A thin plate's face without its far face (both in the capture band,
// measured from opposite sides: FindTwoLayers, FacingOf): the captured
// points on the face's side of the midway plane between the two layers are
// its own, and its outline, the face inside it eroded by the margin and its
// plane are taken from them alone, iterated to their fixed point as the
// plate's first segmentation is. far_face: the far layer's captured points
// inside that eroded outline (those in the margin stay in the edge count).
struct OwnFace {
  PlaneFit fit;
  PlaneOutline outline;
  std::vector<int> face, far_face;  // ascending
};

void RequirePlateCoverage(const PlaneOutline& e, const Artifact& a, const VerifyOptions& o, double capture_band_mm,
                          const std::string& where);

OwnFace SegmentOwnFace(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& captured,
                       const std::vector<int>& far_layer, const PlaneFit& face_fit, double margin_mm, const Artifact& a,
                       const VerifyOptions& o, double capture_band_mm, const std::string& where) {
  OwnFace out;
  out.fit = face_fit;
  // A point on the far layer (its mean): its distance along each round's
  // normal places the far layer whichever sign a refit gives the normal.
  Eigen::Vector3d far_mean_mm = Eigen::Vector3d::Zero();
  for (int i : far_layer) far_mean_mm += pts[i];
  far_mean_mm /= static_cast<double>(far_layer.size());
  for (int round = 0; round < kMaxSegmentationRounds; ++round) {
    const double far_mm = out.fit.normal.dot(far_mean_mm) - out.fit.offset_mm;
    std::vector<int> own, other;
    for (int i : captured) {
      const double d_mm = out.fit.normal.dot(pts[i]) - out.fit.offset_mm;
      (std::abs(d_mm) < std::abs(d_mm - far_mm) ? own : other).push_back(i);
    }
    if (own.size() < 3) throw NotTheArtifactError(where, "the plate's face without its far face holds too few points");
    out.outline = OutlineOfDensePart(pts, own, out.fit.normal);
    RequirePlateCoverage(out.outline, a, o, capture_band_mm, where);
    std::vector<int> next, far_next;
    for (int i : own)
      if (out.outline.InsideEroded(pts[i], margin_mm)) next.push_back(i);
    for (int i : other)
      if (out.outline.InsideEroded(pts[i], margin_mm)) far_next.push_back(i);
    out.far_face.swap(far_next);
    if (round > 0 && next == out.face) break;
    out.face.swap(next);
    out.fit = FitPlaneLeastSquares(pts, out.face);
    if (!out.fit.ok)
      throw NotTheArtifactError(where,
                                "the plate's face without its far face, after the edge margin: " + out.fit.message);
  }
  return out;
}

// The plane found must be the plate: it spans at least `min_coverage` of the
// certified length and width, and no more than the certified size plus twice
// the capture band (what the plate's sides can add). A sphere's cap or a
// table is refused, naming what was found.
void RequirePlateCoverage(const PlaneOutline& e, const Artifact& a, const VerifyOptions& o, double capture_band_mm,
                          const std::string& where) {
  const double longer = std::max(a.plate_length_mm, a.plate_width_mm);
  const double shorter = std::min(a.plate_length_mm, a.plate_width_mm);
  const std::string found = "the plane found spans " + Mm(e.length_mm()) + " x " + Mm(e.width_mm()) +
                            " mm, the plate is " + Mm(longer) + " x " + Mm(shorter) + " mm";
  if (e.length_mm() < o.plate_min_coverage * longer || e.width_mm() < o.plate_min_coverage * shorter) {
    throw NotTheArtifactError(where, found + ": not the plate, or too little of it seen (at least " +
                                         std::to_string(static_cast<int>(std::lround(100 * o.plate_min_coverage))) +
                                         "% of its length and width must be)");
  }
  if (e.length_mm() > longer + 2 * capture_band_mm || e.width_mm() > shorter + 2 * capture_band_mm) {
    throw NotTheArtifactError(
        where, found + ": another surface than the plate lies in its plane (crop the cloud to the plate)");
  }
}

// The balls found are judged whatever their distance (SD fails a rig that
// puts them apart wrongly), with a note beyond 10% of the certificate
// (RadiusToleranceMm's rule; at least twice the MPE): the certificate may be
// another bar's. Refused only beyond a factor 1.5 either way
// (kCertifiedLengthFactor): each ball was found at its certified size
// within 10%, so the rig's scale is right to 10% and only a misregistration
// between the views that see the balls can move them apart, by mm (89 mm
// for an 80 mm bar: FAIL, it read "not this artifact's certificate" and
// blamed the certificate for the rig's error), not by half the bar; bars
// in use differ by more (a 200 mm certificate for an 80 mm bar read SD
// -119.97 mm, FAIL: refused, naming both). 1.5 is also the widest scale
// error ScaleText names.
constexpr double kCertifiedLengthFactor = 1.5;

void RequireCertifiedLength(double distance_mm, const Artifact& a, const std::string& where, ArtifactEvaluation* e) {
  const double ratio = distance_mm / a.center_distance_mm;
  char buf[320];
  if (!(ratio <= kCertifiedLengthFactor && ratio >= 1 / kCertifiedLengthFactor)) {
    std::snprintf(buf, sizeof buf,
                  "the balls are %.2f mm apart (centre to centre) and the certificate says %.2f mm (a factor "
                  "%.2f; a rig that finds each ball at its certified size misplaces them by far less than "
                  "%.1fx): not this artifact's certificate, or not this artifact",
                  distance_mm, a.center_distance_mm, std::max(ratio, 1 / ratio), kCertifiedLengthFactor);
    throw NotTheArtifactError(where, buf);
  }
  const double tolerance_mm = std::max(0.1 * a.center_distance_mm, 2 * a.mpe.sphere_spacing_mm);
  if (std::abs(distance_mm - a.center_distance_mm) <= tolerance_mm) return;
  std::snprintf(buf, sizeof buf,
                "the balls are %.2f mm apart (centre to centre), the certificate says %.2f mm: a certificate "
                "not this bar's? (if it is, the rig misplaced the balls: SD judges it)",
                distance_mm, a.center_distance_mm);
  e->notes.push_back(buf);
}

// The artifact's largest dimension, mm: what a cloud of it must span.
double ArtifactSizeMm(const Artifact& a) {
  switch (a.type) {
    case ArtifactType::kSphere:
      return a.sphere_diameter_mm;
    case ArtifactType::kBallBar:
      return a.center_distance_mm + a.sphere_diameter_mm;
    case ArtifactType::kPlate:
      return std::hypot(a.plate_length_mm, a.plate_width_mm);
  }
  return 0;
}

// "; the whole cloud spans only 0.04 mm across, ..." where a cloud is over
// 100x smaller than the artifact (its bounding box's diagonal against the
// artifact's size), as a cloud in metres is (1000x): RANSAC finding no
// sphere in it said nothing of why. The certificate's sizes are plausible
// (artifact.cc refuses others), so the cloud is the side named: in metres
// where 1000x makes it the artifact's size (within 10x), otherwise not this
// artifact or in another unit. Empty otherwise.
std::string UnitsHint(const Artifact& a, const std::vector<Eigen::Vector3d>& pts) {
  if (pts.empty()) return "";
  Eigen::Vector3d lo = pts[0], hi = pts[0];
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent_mm = (hi - lo).norm(), size_mm = ArtifactSizeMm(a);
  if (!(extent_mm * 100 < size_mm)) return "";
  // Every point the same: a cloud of one point repeated, no extent to
  // compare ("spans only 0 mm across, infx less" said nothing).
  if (extent_mm == 0) return "; every point of the cloud is at the same place: it holds no shape to find";
  const double ratio = size_mm / extent_mm;
  const bool metres = ratio >= 100 && ratio <= 10000;
  // Sized to any double (%g keeps each to a few characters): never cut.
  char buf[256];
  std::snprintf(buf, sizeof buf,
                ratio < 1e6 ? "; the whole cloud spans only %.3g mm across, %.0fx less than the "
                              "artifact's %.4g mm: "
                            : "; the whole cloud spans only %.3g mm across, %.3gx less than the "
                              "artifact's %.4g mm: ",
                extent_mm, ratio, size_mm);
  return buf + std::string(metres ? "is the cloud in metres? verify reads millimetres"
                                  : "the cloud is not of this artifact, or not in millimetres");
}

ArtifactEvaluation EvaluateArtifactInMm(const Artifact& a, const std::vector<Eigen::Vector3d>& pts,
                                        const VerifyOptions& o, const std::string& where,
                                        const std::vector<Eigen::Vector3d>& normals);

}  // namespace

ArtifactEvaluation EvaluateArtifact(const Artifact& a, const std::vector<Eigen::Vector3d>& pts, const VerifyOptions& o,
                                    const std::string& where, const std::vector<Eigen::Vector3d>& normals) {
  if (!normals.empty() && normals.size() != pts.size())
    throw std::invalid_argument("EvaluateArtifact: normals not parallel to the points");
  try {
    return EvaluateArtifactInMm(a, pts, o, where, normals);
  } catch (const NotTheArtifactError& refused) {
    const std::string hint = UnitsHint(a, pts);
    if (hint.empty()) throw;
    throw NotTheArtifactError(refused.where(), refused.problem() + hint);
  }
}

namespace {

ArtifactEvaluation EvaluateArtifactInMm(const Artifact& a, const std::vector<Eigen::Vector3d>& pts,
                                        const VerifyOptions& o, const std::string& where,
                                        const std::vector<Eigen::Vector3d>& normals) {
  o.Check();
  ArtifactEvaluation e;
  e.decision_rule = o.decision_rule;
  e.type = a.type;
  e.points_total = static_cast<int>(pts.size());
  if (e.points_total < o.min_points) {
    // The whole cloud's count (its measured points), before any is found on
    // the artifact: said so, or it read as the artifact's.
    throw NotTheArtifactError(where, "only " + std::to_string(e.points_total) +
                                         " points in the whole cloud; at least " + std::to_string(o.min_points) +
                                         " are needed on the artifact");
  }
  auto require_points = [&](int n, const char* what) {
    if (n < o.min_points) {
      throw NotTheArtifactError(where, std::string("only ") + std::to_string(n) + " points lie on the " + what +
                                           "; at least " + std::to_string(o.min_points) + " are needed");
    }
  };
  switch (a.type) {
    case ArtifactType::kSphere: {
      e.capture_band_mm = CaptureBandMm(o, BandMpeMm(a));
      const ArtifactSphereFit found = FitArtifactSphere(
          pts, 0.5 * a.sphere_diameter_mm, SphereLocateBandMm(o, a.mpe.probing_form_mm, 0.5 * a.sphere_diameter_mm),
          e.capture_band_mm, o);
      if (!found.located) {
        throw NotTheArtifactError(where, "no sphere of the certified size found in the cloud: " + found.fit.message);
      }
      if (!found.fit.ok) throw NotTheArtifactError(where, "the sphere: " + found.fit.message);
      const SphereFit& fit = found.fit;
      const int excluded = found.excluded;
      require_points(static_cast<int>(fit.inliers.size()) + excluded, "sphere");
      e.points_on_artifact = static_cast<int>(fit.inliers.size()) + excluded;
      e.points_excluded = excluded;
      e.points_off_artifact = e.points_total - e.points_on_artifact;  // outside the capture band
      e.sphere_centers_mm = {fit.center_mm};
      e.sphere_diameters_mm = {2 * fit.radius_mm};
      const SphereFitUncertainty u = SphereUncertainty(pts, fit);
      e.sphere_cap_half_angles_deg = {u.cap_half_angle_deg};
      e.sphere_diameter_std_mm = {u.diameter_std_mm};
      e.sphere_noise_variance_inflation = {u.noise_variance_inflation};
      e.sphere_form_mm = {Range(fit.residuals_mm)};
      e.figures = {MakeFigure("P_F", e.sphere_form_mm[0], a.mpe.probing_form_mm),
                   MakeFigure("P_S", 2 * fit.radius_mm - a.sphere_diameter_mm, a.mpe.probing_size_mm)};
      // P_F: the sphere's own form is in the measured range; its certificate
      // (if any) is P_F's uncertainty, as the flatness certificate is F's.
      if (a.sphere_form_uncertainty_mm > 0)
        SetUncertainty(&e.figures[0], std::nullopt, a.StandardUncertaintyMm(a.sphere_form_uncertainty_mm));
      SetUncertainty(&e.figures[1], u.diameter_std_mm, a.StandardUncertaintyMm(a.sphere_diameter_uncertainty_mm));
      ResidualStats(fit.residuals_mm, &e);
      JudgeFigures(o.decision_rule, o, &e.figures);
      e.not_judged_reason =
          NotJudgedReason(e, CapsText(e.sphere_cap_half_angles_deg), a.uncertainty_coverage_factor, o);
      JudgeSurfaceBeyondBand(SphereSurfaceBeyondBand(pts, normals, fit.center_mm, fit.radius_mm, e.capture_band_mm),
                             "the sphere's surface", e.capture_band_mm, &e);
      break;
    }
    case ArtifactType::kBallBar: {
      const double band = CaptureBandMm(o, BandMpeMm(a));
      e.capture_band_mm = band;
      const double r = 0.5 * a.sphere_diameter_mm;
      std::vector<double> all_residuals;
      Eigen::Matrix3d centers_covariance_mm2 = Eigen::Matrix3d::Zero();  // sum of the two balls'
      std::vector<Eigen::Vector3d> remaining = pts;
      int excluded_total = 0, on_artifact = 0;
      // The balls as located (certified size), for a second-pass fit that
      // leaves it: what cap it saw and how well such a cap fits a diameter.
      std::vector<Eigen::Vector3d> located_centers_mm;
      const double tolerance_mm = RadiusToleranceMm(SphereLocateBandMm(o, a.mpe.sphere_spacing_mm, r), r);
      // other_fit: the other ball's free fit, whose size says whether a
      // scale error is plausible (ScaleText; none named if it failed, or if
      // the two fits overlap: two balls cannot, so they are one sphere found
      // twice, and its agreeing with itself is no evidence).
      auto require_certified_size = [&](int ball, const std::vector<int>& indices, const SphereFit& fit,
                                        const SphereFit& other_fit) {
        if (!LeftCertifiedSize(fit, r, tolerance_mm)) return;
        const bool two_balls =
            (fit.center_mm - other_fit.center_mm).norm() >= std::abs(fit.radius_mm) + std::abs(other_fit.radius_mm);
        double other_scale = other_fit.ok && other_fit.converged && two_balls ? other_fit.radius_mm / r : NAN;
        // A scale error scales the bar's length with its balls: where both
        // balls read off the same way but the centres lie the certified
        // distance apart (within the locating band, where that scale would
        // have moved them by more than twice it), the scale is not named (a
        // 38.1 mm certificate for the demo's 25.4 mm balls read "a scale
        // -33% off" with the centres 80.03 mm apart as certified) and the
        // distance is. Not where the centres are merely near it: a ball
        // not located at all leaves the other fit on the rod.
        std::string length_text;
        const double scale = fit.radius_mm / r;
        const double distance_mm = (fit.center_mm - other_fit.center_mm).norm();
        const double locate_mm = SphereLocateBandMm(o, a.mpe.sphere_spacing_mm, r);
        if (fit.ok && fit.converged && two_balls && !ScaleText(scale, other_scale).empty() &&
            std::abs(distance_mm - a.center_distance_mm) <= locate_mm &&
            std::abs(scale - 1) * a.center_distance_mm > 2 * locate_mm) {
          other_scale = NAN;
          char buf[256];
          std::snprintf(buf, sizeof buf,
                        "; both balls read %+.0f%% off, but their centres are %.2f mm apart, as the certificate's "
                        "%.2f mm: no scale error, which would move them too (is the certificate's sphere diameter "
                        "this bar's?)",
                        100 * (scale - 1), distance_mm, a.center_distance_mm);
          length_text = buf;
        }
        throw NotTheArtifactError(
            where, BallText(ball, located_centers_mm[ball]) + ": " +
                       LeftCertifiedSizeText(pts, indices, located_centers_mm[ball], fit, r, tolerance_mm, band,
                                             SphereLocateBandMm(o, a.mpe.sphere_spacing_mm, r), other_scale) +
                       length_text);
      };
      const double cos_cone = std::cos(o.ballbar_shaft_cone_deg * M_PI / 180.0);
      OtherBallScaleAt first_ball_scale_at;  // for ball 2's search
      for (int ball = 0; ball < 2; ++ball) {
        const ArtifactSphereFit found =
            FitArtifactSphere(remaining, r, SphereLocateBandMm(o, a.mpe.sphere_spacing_mm, r), band, o,
                              first_ball_scale_at, /*first_of_ball_bar=*/ball == 0);
        if (!found.located) {
          throw NotTheArtifactError(
              where, "ball " + std::to_string(ball + 1) + " of the ball bar not found: " + found.fit.message);
        }
        // A ball located at the certified size whose free fit then left it
        // (or failed) is not judged here: its capture band still holds the
        // shaft's points, which the second pass below removes before it
        // judges the size (seen by one module, the rod pulled the demo's
        // 25.4 mm balls to a 30.1 mm fit). Until then the ball is the sphere
        // located.
        const SphereFit fit = found.fit.ok
                                  ? found.fit
                                  : SphereAt(remaining, WithinSphereShell(remaining, found.located_center_mm, r, band),
                                             found.located_center_mm, r);
        const int excluded = found.fit.ok ? found.excluded : 0;
        // Ball 1's size as evidence of a scale error for ball 2's search
        // (ScaleText): its free fit outside the shaft cone towards where
        // ball 2 is, as the second pass fits it. Not its first fit: that
        // held the rod's points in its band, which pulled the demo's
        // 25.4 mm balls (one module's view) to 30.1 mm, and a truly larger
        // ball 2 then read as the same scale error.
        if (ball == 0) {
          first_ball_scale_at = [&pts, center = fit.center_mm, radius = fit.radius_mm, r, band, cos_cone](
                                    const Eigen::Vector3d& ball_2_center_mm, double ball_2_radius_mm) {
            return internal::BallScaleOffShaft(pts, center, radius, r, band, cos_cone, ball_2_center_mm,
                                               ball_2_radius_mm);
          };
        }
        located_centers_mm.push_back(found.located_center_mm);
        require_points(static_cast<int>(fit.inliers.size()) + excluded, "ball bar's spheres");
        excluded_total += excluded;
        on_artifact += static_cast<int>(fit.inliers.size()) + excluded;
        e.sphere_centers_mm.push_back(fit.center_mm);
        e.sphere_diameters_mm.push_back(2 * fit.radius_mm);
        all_residuals.insert(all_residuals.end(), fit.residuals_mm.begin(), fit.residuals_mm.end());
        // Remove everything near this ball before looking for the other one.
        std::vector<Eigen::Vector3d> rest;
        for (const auto& p : remaining)
          if ((p - fit.center_mm).norm() > fit.radius_mm + band) rest.push_back(p);
        remaining.swap(rest);
      }
      // Second pass: with both centres known, each ball's points are those
      // within the capture band of its sphere and outside the shaft's cone about the
      // bar axis; the sets and fits are iterated to their fixed point, then
      // the worst points are excluded and each ball is refitted.
      {
        std::vector<Eigen::Vector3d> centers = e.sphere_centers_mm;
        std::vector<double> radii = {0.5 * e.sphere_diameters_mm[0], 0.5 * e.sphere_diameters_mm[1]};
        std::vector<int> idx[2];
        for (int round = 0; round < kMaxSegmentationRounds; ++round) {
          bool changed = false;
          std::vector<int> next[2];
          for (int ball = 0; ball < 2; ++ball) {
            next[ball] = BallPointsOffShaft(pts, centers[ball], radii[ball], band, centers[1 - ball], cos_cone);
            require_points(static_cast<int>(next[ball].size()), "ball bar's spheres (outside the shaft cone)");
            changed = changed || next[ball] != idx[ball];
          }
          if (!changed) break;
          // Both balls refitted before either's size is judged: a scale
          // error shows as both off the same way (ScaleText).
          SphereFit fits[2];
          for (int ball = 0; ball < 2; ++ball) {
            idx[ball].swap(next[ball]);
            fits[ball] = RefineSphere(pts, idx[ball], centers[ball], radii[ball], kRefineIterations);
          }
          for (int ball = 0; ball < 2; ++ball) require_certified_size(ball, idx[ball], fits[ball], fits[1 - ball]);
          for (int ball = 0; ball < 2; ++ball) {
            centers[ball] = fits[ball].center_mm;
            radii[ball] = fits[ball].radius_mm;
          }
        }
        all_residuals.clear();
        excluded_total = 0;
        on_artifact = 0;
        e.sphere_cap_half_angles_deg.clear();
        e.sphere_diameter_std_mm.clear();
        e.sphere_noise_variance_inflation.clear();
        e.sphere_form_mm.clear();
        SphereFit fits[2];
        std::vector<int> kept[2];
        int excluded[2] = {0, 0};
        for (int ball = 0; ball < 2; ++ball) {
          std::vector<double> res;
          for (int i : idx[ball]) res.push_back((pts[i] - centers[ball]).norm() - radii[ball]);
          kept[ball] = ExcludeWorst(idx[ball], res, o.excluded_fraction_max, &excluded[ball]);
          fits[ball] = RefineSphere(pts, kept[ball], centers[ball], radii[ball], kRefineIterations);
        }
        for (int ball = 0; ball < 2; ++ball) require_certified_size(ball, kept[ball], fits[ball], fits[1 - ball]);
        for (int ball = 0; ball < 2; ++ball) {
          const SphereFit& fit = fits[ball];
          e.sphere_centers_mm[ball] = fit.center_mm;
          e.sphere_diameters_mm[ball] = 2 * fit.radius_mm;
          const SphereFitUncertainty u = SphereUncertainty(pts, fit);
          e.sphere_cap_half_angles_deg.push_back(u.cap_half_angle_deg);
          e.sphere_diameter_std_mm.push_back(u.diameter_std_mm);
          e.sphere_noise_variance_inflation.push_back(u.noise_variance_inflation);
          e.sphere_form_mm.push_back(Range(fit.residuals_mm));
          centers_covariance_mm2 += u.center_covariance_mm2;
          all_residuals.insert(all_residuals.end(), fit.residuals_mm.begin(), fit.residuals_mm.end());
          excluded_total += excluded[ball];
          on_artifact += static_cast<int>(idx[ball].size());
        }
      }
      e.points_on_artifact = on_artifact;
      e.points_excluded = excluded_total;
      e.points_off_artifact = e.points_total - e.points_on_artifact;  // outside both balls' bands, or in the cone
      const Eigen::Vector3d bar_mm = e.sphere_centers_mm[0] - e.sphere_centers_mm[1];
      RequireCertifiedLength(bar_mm.norm(), a, where, &e);
      e.figures = {MakeFigure("SD", bar_mm.norm() - a.center_distance_mm, a.mpe.sphere_spacing_mm)};
      // The two centres' errors are independent (disjoint points); the
      // distance moves with their difference along the bar.
      const Eigen::Vector3d along = bar_mm.normalized();
      const double variance_mm2 = along.dot(centers_covariance_mm2 * along);
      SetUncertainty(&e.figures[0],
                     variance_mm2 > 0 && std::isfinite(variance_mm2) ? std::sqrt(variance_mm2)
                                                                     : std::numeric_limits<double>::infinity(),
                     a.StandardUncertaintyMm(a.center_distance_uncertainty_mm));
      ResidualStats(all_residuals, &e);
      JudgeFigures(o.decision_rule, o, &e.figures);
      e.not_judged_reason =
          NotJudgedReason(e, CapsText(e.sphere_cap_half_angles_deg), a.uncertainty_coverage_factor, o);
      for (int ball = 0; ball < 2; ++ball) {
        const Eigen::Vector3d& c = e.sphere_centers_mm[ball];
        JudgeSurfaceBeyondBand(SphereSurfaceBeyondBand(pts, normals, c, 0.5 * e.sphere_diameters_mm[ball], band,
                                                       (e.sphere_centers_mm[1 - ball] - c).normalized(), cos_cone),
                               "ball " + std::to_string(ball + 1) + "'s surface", band, &e);
      }
      break;
    }
    case ArtifactType::kPlate: {
      e.capture_band_mm = CaptureBandMm(o, BandMpeMm(a));
      PlaneFitOptions po;
      po.inlier_threshold_mm = LocateBandMm(o, a.mpe.flatness_mm);
      po.seed = o.seed;
      PlaneFit fit = FitPlaneRobust(pts, po);
      if (!fit.ok) throw NotTheArtifactError(where, "no plane found in the cloud: " + fit.message);
      // The face: the points within the capture band of the plane, inside
      // the outline of their dense part (plate_outline.h: a few stray points
      // do not widen it) eroded by the edge margin; the set and the
      // least-squares plane iterated to their fixed point.
      std::vector<int> face, captured;
      PlaneOutline extent;  // of `captured`, whose points inside it eroded are `face`
      // The outline's sides pass through its outermost points: on it is in
      // (1 um, for rounding). With no edge margin the face is every captured
      // point inside the outline so taken, and none is in the margin (the
      // strict erosion by 0 left the outermost points in it).
      constexpr double kOnOutlineMm = 1e-3;
      const double face_margin_mm = o.plate_edge_margin_mm > 0 ? o.plate_edge_margin_mm : -kOnOutlineMm;
      for (int round = 0; round < kMaxSegmentationRounds; ++round) {
        captured = WithinPlaneBand(pts, fit, e.capture_band_mm);
        extent = OutlineOfDensePart(pts, captured, fit.normal);
        RequirePlateCoverage(extent, a, o, e.capture_band_mm, where);
        e.plate_outline_length_mm = extent.length_mm();
        e.plate_outline_width_mm = extent.width_mm();
        std::vector<int> next;
        for (int i : captured)
          if (extent.InsideEroded(pts[i], face_margin_mm)) next.push_back(i);
        if (round > 0 && next == face) break;
        face.swap(next);
        fit = FitPlaneLeastSquares(pts, face);
        if (!fit.ok)
          throw NotTheArtifactError(where, "the plate's face is too small after the edge margin: " + fit.message);
      }
      require_points(static_cast<int>(fit.inliers.size()), "plate");
      // Two layers in the band: the far face of a plate thinner than it,
      // measured from the other side, is left out and F judged on the face
      // (the larger layer); otherwise F spans both, and fails a module that
      // far off, as it must. Either way a note says what was found.
      std::vector<int> far_face;  // ascending
      if (TwoLayers two = FindTwoLayers(pts, face, fit, a, o); two.found) {
        const LayersFacing facing = FacingOf(normals, two, fit.normal);
        if (facing == LayersFacing::kOppositeSides) {
          // The face alone, segmented again: its outline, edge margin and
          // plane from its own points. The outline of both faces' points is
          // the larger of the two, and its erosion left the face's own edge
          // (its chamfer, its sides) in F: F read 0.45 mm for a face whose
          // own eroded outline holds 0.41 mm, and changed with the band.
          fit = FitPlaneLeastSquares(pts, two.larger);
          if (!fit.ok) throw NotTheArtifactError(where, "the plate's face without its far face: " + fit.message);
          const OwnFace own =
              SegmentOwnFace(pts, captured, two.smaller, fit, face_margin_mm, a, o, e.capture_band_mm, where);
          fit = own.fit;
          face = own.face;
          far_face = own.far_face;
          extent = own.outline;
          e.plate_outline_length_mm = extent.length_mm();
          e.plate_outline_width_mm = extent.width_mm();
          two.smaller = far_face;
          require_points(static_cast<int>(fit.inliers.size()), "plate (its far face left out)");
        }
        e.notes.push_back(TwoLayersNote(two, facing, !normals.empty(), e.capture_band_mm));
      }
      e.plate_points_far_face = static_cast<int>(far_face.size());
      // Where the captured points off the face are: on its far face, outside
      // the outline, or in the edge margin inside it (face, far_face and
      // captured are all ascending).
      e.plate_points_off_outline = extent.points_outside;
      e.plate_points_outside_rectangle = 0;
      for (size_t k = 0, f = 0, g = 0; k < captured.size(); ++k) {
        if (f < face.size() && face[f] == captured[k]) {
          ++f;
        } else if (g < far_face.size() && far_face[g] == captured[k]) {
          ++g;
        } else if (extent.InsideEroded(pts[captured[k]], -kOnOutlineMm)) {
          ++e.points_in_edge_margin;
        } else {
          ++e.plate_points_outside_rectangle;
        }
      }
      e.points_off_artifact = e.points_total - static_cast<int>(captured.size()) + e.plate_points_outside_rectangle +
                              e.plate_points_far_face;
      int excluded = 0;
      const std::vector<int> kept = ExcludeWorst(fit.inliers, fit.residuals_mm, o.excluded_fraction_max, &excluded);
      fit = FitPlaneLeastSquares(pts, kept);
      e.points_on_artifact = static_cast<int>(kept.size()) + excluded;
      e.points_excluded = excluded;
      e.plane_normal = fit.normal;
      e.plane_offset_mm = fit.offset_mm;
      e.figures = {MakeFigure("F", Range(fit.residuals_mm), a.mpe.flatness_mm)};
      // F is a range of residuals: no fit covariance; the certificate's
      // uncertainty of the plate's flatness is its uncertainty, and without
      // one F has none to report (not 0: a range varies from sample to
      // sample, ~0.01 mm over 20 000-point simulated plates).
      if (a.flatness_uncertainty_mm > 0)
        SetUncertainty(&e.figures[0], std::nullopt, a.StandardUncertaintyMm(a.flatness_uncertainty_mm));
      ResidualStats(fit.residuals_mm, &e);
      JudgeFigures(o.decision_rule, o, &e.figures);
      e.not_judged_reason = NotJudgedReason(e, "", a.uncertainty_coverage_factor, o);
      const int face_side = SideMeasuredFrom(normals, face, fit.normal);
      JudgePlateFaceBeyondBand(PlateSurfaceBeyondBand(pts, normals, fit.normal, fit.offset_mm, face_side, extent,
                                                      std::max(0.0, o.plate_edge_margin_mm), e.capture_band_mm),
                               face_side, e.capture_band_mm, &e);
      break;
    }
  }
  return e;
}

}  // namespace

ArtifactEvaluation NotEvaluated(const Artifact& a, const VerifyOptions& o, int points_total,
                                const std::string& reason) {
  ArtifactEvaluation e;
  e.type = a.type;
  e.decision_rule = o.decision_rule;
  e.points_total = points_total;
  e.capture_band_mm = CaptureBandMm(o, BandMpeMm(a));
  e.evaluated = false;
  e.not_judged_reason = "not evaluated: " + reason;
  return e;
}

VerifySummary Summarise(const std::vector<ArtifactEvaluation>& positions) {
  VerifySummary s;
  s.pass = !positions.empty();
  std::map<std::string, std::pair<Figure, int>> worst;  // name -> the figure, its position
  for (size_t i = 0; i < positions.size(); ++i) {
    const ArtifactEvaluation& p = positions[i];
    if (!p.judged()) {
      s.not_judged_positions.push_back(static_cast<int>(i));
      s.pass = false;
      continue;
    }
    auto judged_magnitude = [&p](const Figure& f) {
      return JudgedMagnitudeMm(p.decision_rule, f.value_mm, f.ExpandedUncertaintyMm());
    };
    for (const Figure& f : p.figures) {
      s.pass = s.pass && f.pass;
      // A figure left undetermined in a position that fails by another is
      // not a measurement of the system: not the worst.
      if (!f.judged) continue;
      auto it = worst.find(f.name);
      if (it == worst.end() || judged_magnitude(f) > judged_magnitude(it->second.first))
        worst[f.name] = {f, static_cast<int>(i)};
    }
  }
  for (const auto& [name, at] : worst) {
    s.worst.push_back(at.first);
    s.worst_positions.push_back(at.second);
  }
  return s;
}

}  // namespace stereorig
