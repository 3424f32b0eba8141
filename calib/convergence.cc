#include "calib/convergence.h"

#include <cmath>

#include "calib/core/number_text.h"

namespace stereorig {
namespace {

// An RMS over the limit, or one that is not a number (a solve that failed
// outright leaves NaN).
bool Over(double rms_px, double max_rms_px) { return !(rms_px <= max_rms_px); }

std::string Px(double x) { return NumberText(x, 4) + " px"; }

}  // namespace

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
  // Stage 3's robust loss leaves a few corners out by design (a capture in
  // which the board moved between two modules' exposures): its RMS counts
  // them in full, its median corner residual does not. Half the corners
  // off by more than the limit is no such few.
  if (report.num_modules > 1 && !report.stereo.empty() &&
      Over(report.system.refined_median_corner_residual_px, max_rms_px))
    return "stage 3 did not converge: half its corners are off by more than " +
           Px(report.system.refined_median_corner_residual_px) + " (rms " +
           Px(report.system.refined_reprojection_rms_px) + "), " + limit +
           " (each module converged alone, so the modules do not see the board in one place: a module that moved "
           "between captures, or a target whose back face is not where the target file puts it)";
  return "";
}

}  // namespace stereorig
