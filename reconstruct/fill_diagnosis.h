// Where and why the fill is lost: a module's result laid beside the
// simulator's truth on the rectified left grid.
//
// fill_score.h counts the target pixels (object, seen by both cameras, grid
// lit) and the test that lost each. This goes one step further, for tuning:
//   - the truth disparity of every rectified left pixel (the truth depth map
//     sampled through the runtime's rectification, re-projected with the
//     runtime's own rectified geometry, so it is what a perfect matcher would
//     return on the calibrated rig);
//   - for every lost target pixel, whether the matcher's own acceptance test
//     (RefineAcceptance, disparity_state.h) passes when the Lucas-Kanade
//     refinement starts from the truth with the truth's slopes: "reachable"
//     pixels were lost by the search or the growing, the others by the image
//     (or by a test that is too strict there);
//   - for every point, its disparity error against the truth.
// EncodeFillDiagnosisImages() encodes PNGs of these for viewing (`stereorig
// score --diagnose` writes them with its report, all or none).
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "reconstruct/disparity_state.h"
#include "reconstruct/runtime.h"

namespace stereorig {

// CV_32FC1 on the module's rectified left grid: the image disparity (px,
// rectify.h) of the surface the truth depth map puts behind each pixel, NaN
// where there is none or the depth jumps within the 2x2 pixels sampled (an
// edge). `left_depth_mm`: the truth depth map of the module's left camera
// (fill_score.h, CameraTruthMaps::depth_mm). left_x, left_y: the left
// view's exact float remap table (rectify.h, BuildRectifyMap).
cv::Mat TruthDisparity(const ModulePlan& plan, const cv::Mat& left_x, const cv::Mat& left_y,
                       const cv::Mat& left_depth_mm);

// The module's rectified pair, as the runtime rectifies it.
void RectifyModulePair(const Rig& rig, const ModulePlan& plan, const std::vector<cv::Mat>& images, cv::Mat* left,
                       cv::Mat* right);

// The truth disparity's slope along a row or column (px per px) at a pixel
// holding `centre_px`, from its neighbours before and after (NaN = no truth):
// the central difference where both exist (the centre need not), the
// one-sided one where only one does and the centre has truth (a silhouette
// or a depth edge), else 0.
double TruthSlopePx(float before_px, float centre_px, float after_px);

// The points' signed disparity error d - truth by their distance along the
// row to the object's silhouette: the nearest pixel of the row without
// truth (NaN), to the right and to the left. Neither the image's own border
// nor, given `left_valid`, the edge of the left view's data (rectified
// pixels whose source is off the sensor: NaN there too) is a silhouette.
// A window-based match near a silhouette measures the surface a little
// inside it, where the image blur and the truncated pixel footprint put the
// intensity; on a limb seen at a grazing angle that is a different
// disparity (docs/reconstruct-log.md, "Points at a silhouette (session
// 19)"). The count of points > 1 px off in each bin tells a shift of the
// whole bin from a few gross mismatches pulling its mean.
struct SilhouetteErrorProfile {
  static constexpr int kMaxDistancePx = 6;  // nearer ones are binned by distance; the rest are "interior"
  // Index k = 1..kMaxDistancePx: the points k px from the silhouette on
  // that side (silhouette at x + k on the right, x - k on the left; a point
  // near both counts in both). Index 0 is unused.
  std::array<int, kMaxDistancePx + 1> right_count{}, left_count{};
  std::array<int, kMaxDistancePx + 1> right_off_1px{}, left_off_1px{};  // of those, |d - truth| > 1 px
  std::array<double, kMaxDistancePx + 1> right_mean_px{}, left_mean_px{};
  int interior_count = 0;  // farther than kMaxDistancePx from both
  int interior_off_1px = 0;
  double interior_mean_px = 0;
  std::string Summary() const;  // one line
};

// Over the pixels of `status` (CV_8UC1 PixelStatus) that are points, with
// a finite disparity in `disparity_px` and a truth in `truth_disparity`
// (both CV_32FC1, the status's size). left_valid: CV_8UC1 of that size
// (ModulePlan::left_valid), 0 where the left view has no data; empty: all
// have.
SilhouetteErrorProfile ProfileSilhouetteError(const cv::Mat& disparity_px, const cv::Mat& truth_disparity,
                                              const cv::Mat& status, const cv::Mat& left_valid = cv::Mat());

struct FillDiagnosis {
  cv::Mat left, right;      // CV_8UC1 rectified pair
  cv::Mat target;           // CV_8UC1: 255 = fill target (fill_score.h), rectified grid
  cv::Mat truth_disparity;  // CV_32FC1, NaN = none
  cv::Mat status;           // CV_8UC1 PixelStatus (ModuleReport::status)
  cv::Mat disparity_px;     // CV_32FC1: the matcher's disparity (+inf = none); from a second Match() run
  cv::Mat truth_status;     // CV_8UC1 PixelStatus of Accept() refined from the truth (lost targets only; else 0)
  cv::Rect match_roi;
  // Target pixels lost, by final status (rows) and by whether the truth is
  // reachable (the refinement from the truth passes Accept and stays within
  // 0.5 px of it): lost[status][0] = reachable, [1] = not.
  std::vector<std::array<int, 2>> lost = std::vector<std::array<int, 2>>(size_t(PixelStatus::kNumStatus));
  // Of the unreachable ones: the status Accept gives from the truth.
  std::vector<int> unreachable_by = std::vector<int>(size_t(PixelStatus::kNumStatus), 0);
  // Target pixels and filled ones by the truth's foreshortening of the
  // right view against the left, 1 - dd/dx (< 1: the right camera sees the
  // surface more obliquely), binned at kForeshorteningEdges.
  static constexpr std::array<double, 7> kForeshorteningEdges = {0.3, 0.5, 0.7, 0.9, 1.1, 1.5, 2.0};
  std::array<int, 8> target_by_foreshortening{}, filled_by_foreshortening{};
  int unreachable_oblique_ok = 0;  // unreachable ones the oblique refinement (oblique_refine.h) reaches from the truth
  int target_px = 0, filled_px = 0;
  int points_with_truth = 0, points_off_1px = 0;  // points with a truth disparity; of those, > 1 px off
  double mean_abs_error_px = 0;                   // of the points within 1 px
  SilhouetteErrorProfile silhouette;              // the points' error near the silhouette
  std::string Summary() const;                    // a few lines of text
};

// `rec`/`runtime`: the reconstruction of `images`; `target_original`:
// FillTargetMask() of the module; `left_depth_mm`: truth depth of its left
// camera.
FillDiagnosis DiagnoseFill(const Runtime& runtime, int module, const std::vector<cv::Mat>& images,
                           const Reconstruction& rec, const cv::Mat& target_original, const cv::Mat& left_depth_mm);

// The PNG files `prefix`_{left,status,lost,error}.png, cropped to the match
// ROI, as (path, bytes) for the caller to write (none for an empty ROI):
// status = colour per PixelStatus over the grey image (targets outlined);
// lost = lost targets, green where reachable, red where not; error = |d - truth|.
// Encoded, not written: `stereorig score` writes every scene's with its
// report, all or none, so that a later scene's bad input leaves none.
std::vector<std::pair<std::string, std::string>> EncodeFillDiagnosisImages(const FillDiagnosis& d,
                                                                           const std::string& prefix);

// The BGR colour of `status` in the status image (docs/reconstruct.md,
// `--diagnose`): each loss its own, except off_plane_coarse drawn with
// off_plane; white for the statuses no target pixel should hold
// (not_searched, out_of_range, low_confidence, outside_volume, object_size).
cv::Vec3b DiagnosisColour(PixelStatus status);

// The files EncodeFillDiagnosisImages encodes for `prefix` (a command claims
// them before any work): prefix_left.png, _status.png, _lost.png, _error.png.
std::vector<std::string> FillDiagnosisImagePaths(const std::string& prefix);

// The prefix `stereorig score --diagnose` gives module `module` of `scene`:
// DIR/<scene>_m<module>.
std::string FillDiagnosisPrefix(const std::string& dir, const std::string& scene, int module);

}  // namespace stereorig
