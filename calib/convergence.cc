#include "calib/convergence.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "calib/core/number_text.h"

namespace stereorig {
namespace {

// An RMS over the limit, or one that is not a number (a solve that failed
// outright leaves NaN).
bool Over(double rms_px, double max_rms_px) { return !(rms_px <= max_rms_px); }

std::string Px(double x) { return NumberText(x, 4) + " px"; }

// Stage 3's captures over the limit, worst first (at most 3; the worst
// alone where none is), each with its RMS and corners, and the worst's RMS
// over the median capture's. Each capture's RMS is over its own corners'
// residual coordinates, as the stage's is over all of them.
std::string WorstCaptures(const CalibrationReport& report, double max_rms_px) {
  const std::vector<SystemReport::CaptureRms>& c = report.system.refined_capture_rms;  // worst first
  if (c.empty()) return "";
  std::vector<double> rms_px;
  for (const SystemReport::CaptureRms& x : c) rms_px.push_back(x.rms_px);
  std::sort(rms_px.begin(), rms_px.end());
  const size_t n = rms_px.size();
  const double median_px = n % 2 ? rms_px[n / 2] : 0.5 * (rms_px[n / 2 - 1] + rms_px[n / 2]);
  size_t over = 0;
  while (over < c.size() && Over(c[over].rms_px, max_rms_px)) ++over;
  std::string out = over > 1 ? "; its worst captures " : "; its worst capture ";
  for (size_t i = 0; i < std::max<size_t>(1, std::min<size_t>(over, 3)); ++i)
    out += (i ? ", " : "") + report.CaptureName(c[i].capture) + " at rms " + Px(c[i].rms_px) + " over " +
           std::to_string(c[i].corners) + " corners";
  out += " (" + std::to_string(over) + " of " + std::to_string(c.size()) + " captures over the limit)";
  out += ", the median capture at rms " + Px(median_px);
  if (median_px > 0) out += ": the worst " + NumberText(c[0].rms_px / median_px, 3) + " times it";
  return out;
}

// Stage 3's cameras whose corners are not the noise stage 2 measured on
// them (NotConvergedProblem, below), worst first by their figure's ratio to
// its limit, at most two named and the others counted; "" if none.
std::string CamerasOverTheirNoise(const CalibrationReport& report, double max_rms_px) {
  struct Over {
    double ratio = 0.0;
    std::string text;
  };
  std::vector<Over> over;
  for (const SystemReport::CameraResiduals& c : report.system.refined_camera_residuals) {
    const Stage3CameraLimits l = Stage3CameraLimitsOf(report, c.camera, max_rms_px);
    if (!(l.sigma_px > 0) || c.corners == 0) continue;
    if (c.median_px <= l.median_px && c.p90_px <= l.p90_px) continue;
    std::string name = "camera " + std::to_string(c.camera);
    for (const StereoReport& m : report.stereo)
      for (const IntrinsicsReport* x : {&m.left, &m.right})
        if (x->camera == c.camera)
          name += " (" + (x->camera_name.empty() ? "" : x->camera_name + " of ") + m.module_name + ")";
    over.push_back({std::max(c.median_px / l.median_px, c.p90_px / l.p90_px),
                    name + " at a median distance of " + Px(c.median_px) + " and a 90th percentile of " + Px(c.p90_px) +
                        " over " + std::to_string(c.corners) + " corners, against " + Px(l.median_px) + " and " +
                        Px(l.p90_px) + " for its stage 2 noise of " + Px(l.sigma_px) +
                        (l.floor_sets_them ? " and the floor of " + Px(l.floor_px) + " (" +
                                                 NumberText(kStage3ExcessFloorOfLimit) + " x --max-rms-px)"
                                           : std::string())});
  }
  std::stable_sort(over.begin(), over.end(), [](const Over& a, const Over& b) { return a.ratio > b.ratio; });
  std::string out;
  for (size_t i = 0; i < std::min<size_t>(2, over.size()); ++i) out += (i ? "; " : "") + over[i].text;
  if (over.size() > 2) out += "; and " + std::to_string(over.size() - 2) + " other camera(s)";
  return out;
}

}  // namespace

Stage3CameraLimits Stage3CameraLimitsOf(const CalibrationReport& report, int camera, double max_rms_px) {
  Stage3CameraLimits l;
  // Stage 2's noise of the camera: the RMS of its inlier corners' residual
  // coordinates in its module's joint solve, where every capture has its own
  // board pose for that module alone, so that a module moved between
  // captures leaves it at the noise (the module is rigid within itself).
  // The module's RMS where the camera's is not given.
  for (const StereoReport& m : report.stereo)
    for (const IntrinsicsReport* c : {&m.left, &m.right})
      if (c->camera == camera) l.sigma_px = c->rms_px > 0 ? c->rms_px : m.rms_px;
  // What stage 3 may add to it: as much again as the noise itself, in
  // quadrature (its variance doubled), and at least a tenth of the limit.
  l.floor_px = kStage3ExcessFloorOfLimit * max_rms_px;
  l.floor_sets_them = l.sigma_px < l.floor_px;
  const double spread_px = std::hypot(l.sigma_px, std::max(l.sigma_px, l.floor_px));
  l.median_px = kRayleighMedian * spread_px;
  l.p90_px = kRayleighP90 * spread_px;
  return l;
}

std::string NotConvergedProblem(const CalibrationReport& report, double max_rms_px) {
  const std::string limit = "over --max-rms-px " + NumberText(max_rms_px);
  // The earliest stage over the limit is named, each of its cameras or
  // modules: the later stages start from its result, so theirs follow from it.
  std::string cameras;
  for (const IntrinsicsReport& r : report.intrinsics) {
    if (!Over(r.rms_px, max_rms_px)) continue;
    cameras += cameras.empty() ? "" : ", ";
    cameras += "camera " + std::to_string(r.camera) + " (" + r.camera_name + ") at rms " + Px(r.rms_px) + " with " +
               std::to_string(r.num_outliers) + " outlier corner(s)";
    if (!r.worst_views.empty())
      cameras +=
          ", worst view capture " + report.CaptureName(r.worst_views[0].capture) + " at " + Px(r.worst_views[0].rms_px);
  }
  if (!cameras.empty())
    return "stage 1 did not converge: " + cameras + ", " + limit +
           " (a camera that converged shows its corners' noise, a few tenths of a px at most): give the lens's "
           "focal length with --focal, a lens model that holds the lens with --lensmodel, or more views reaching the "
           "imager's corners, and look at the worst view";
  std::string modules;
  for (const StereoReport& s : report.stereo) {
    if (!Over(s.rms_px, max_rms_px)) continue;
    modules += modules.empty() ? "" : ", ";
    modules +=
        s.module_name + " at rms " + Px(s.rms_px) + " with " + std::to_string(s.num_outliers) + " outlier corner(s)";
  }
  if (!modules.empty())
    return "stage 2 did not converge: " + modules + ", " + limit +
           " (each camera converged alone, so its two cameras do not see the board in one place: images of a "
           "capture not taken at the same moment, or cameras that moved between captures)";
  // Stage 3 is held to the limit by its RMS, as stages 1 and 2 are: over
  // every corner it adjusted (those stages 1 and 2 judged outliers are left
  // out before it), those its Huber loss down-weights counted in full. Its
  // median corner residual alone let a capture whose module 1 images were
  // another capture's pass (rms 24.4 px, median 0.15 px): the loss bounded
  // that capture's pull, not its effect, and S moved 2.2 mm from the same
  // captures without it. Half the corners over the limit fails it too:
  // the median is of the corners' residual distances hypot(du, dv), and the
  // limit is on an RMS over coordinates; for Gaussian residuals of sigma per
  // coordinate the median distance is sigma sqrt(2 ln 2) = 1.1774 sigma, so
  // it is held to that multiple of the limit (held to the limit itself,
  // stage 3 was refused at a per-coordinate RMS of 0.85 px).
  const SystemReport& s = report.system;
  if (report.num_modules <= 1 || report.stereo.empty()) return "";
  const double median_limit_px = std::sqrt(2.0 * std::log(2.0)) * max_rms_px;
  const bool over =
      Over(s.refined_reprojection_rms_px, max_rms_px) || Over(s.refined_median_corner_residual_px, median_limit_px);
  // Residuals that could not be evaluated read NaN: the solver's line says why.
  const bool read = std::isfinite(s.refined_reprojection_rms_px) && std::isfinite(s.refined_median_corner_residual_px);
  if (over && (read || s.solver_problem.empty())) {
    // The figure that failed, against its own limit: the rms against
    // --max-rms-px, else the median against its multiple of it (an rms
    // within the limit must not read as over it).
    const bool rms_over = Over(s.refined_reprojection_rms_px, max_rms_px);
    const std::string figures =
        rms_over ? "rms " + Px(s.refined_reprojection_rms_px) + " (half its corners off by more than " +
                       Px(s.refined_median_corner_residual_px) + "), " + limit
                 : "half its corners off by more than " + Px(s.refined_median_corner_residual_px) +
                       ", over sqrt(2 ln 2) x --max-rms-px = " + Px(median_limit_px) +
                       " (the median distance of corners whose coordinates have an rms of --max-rms-px; its rms " +
                       Px(s.refined_reprojection_rms_px) + " is within " + NumberText(max_rms_px) + " px)";
    return "stage 3 did not converge: " + figures + WorstCaptures(report, max_rms_px) +
           " (each module converged alone, so the modules do not see the board in one place: one capture far over "
           "the others is one whose modules' images were not taken at the same moment, to remove or take again; "
           "many, a module that moved between captures, or a target whose back face is not where the target file "
           "puts it)";
  }
  // A solve that stopped short (Ceres's iteration limit, a failure, or
  // residuals that could not be evaluated) left S wherever it stopped,
  // whatever its RMS reads. After the RMS: captures that do not agree stop
  // it short too, and the RMS's message names them.
  if (!s.solver_problem.empty())
    return "stage 3 did not converge: " + s.solver_problem +
           (std::isfinite(s.refined_reprojection_rms_px) ? ", at rms " + Px(s.refined_reprojection_rms_px) : "") +
           ": S, the stereo pairs and the lenses are wherever the solve stopped (" +
           (s.solver_at_iteration_limit
                ? "it reached its iteration limit, --max-iterations " + std::to_string(s.max_iterations) +
                      ": a solve still converging needs a higher one; one that does not converge, "
                : std::string()) +
           "a lens model whose distortions the corners do not determine: try a simpler --lensmodel or "
           "--fixed-intrinsics)";
  // Within the limit, stage 3 must still be the noise its corners showed
  // in stage 2 (after the solver: the residuals of a solve that stopped
  // short say nothing of the rig). See kStage3ExcessFloorOfLimit.
  const std::string cameras_over = CamerasOverTheirNoise(report, max_rms_px);
  if (!cameras_over.empty())
    return "stage 3 did not converge: its corners are off by more than the noise stage 2 measured on them: " +
           cameras_over +
           " (the limits: the median and 90th percentile of corner distances whose coordinates have that noise and "
           "as much again, or that noise and the floor where the noise is less than the floor; each module alone fits "
           "its corners at that noise, so the modules did not stay in one "
           "place relative to each other over the captures: a module that moved between captures, modules whose "
           "images were not taken at the same moment, or a target whose back face is not where the target file "
           "puts it)";
  return "";
}

std::string HornOnlyWarning(const SystemReport& s) {
  if (s.horn_only_solver_problem.empty()) return "";
  const bool evaluated = std::isfinite(s.horn_reprojection_rms_px);
  const std::string rms = "its rms (the report's horn_only, the rig file's rig_horn_only_rms_px) is ";
  return "stage 3's Horn-only solve (S and the stereo pairs held at Horn's and stage 2's, the board poses solved) " +
         std::string(s.horn_only_stopped_short ? "did not converge: " : "converged, but ") +
         s.horn_only_solver_problem + ": " + rms +
         (evaluated ? "where it stopped, not what Horn's S gives" : "not a number") +
         "; the full adjustment started from " + (s.horn_only_stopped_short ? "there" : "its solution") +
         " and is judged on its own" +
         (s.horn_only_stopped_short ? " (--max-iterations raises the limit of both)" : "");
}

}  // namespace stereorig
