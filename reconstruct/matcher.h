// Dense correspondence on a rectified 8-bit pair: the `match` stage of the
// runtime, filtering and sub-pixel refinement included.
//
// Our matcher (MatcherKind::kCensusSgm) is coarse-to-fine:
//   1. at the coarsest pyramid level (images halved `pyramid_levels` times),
//      census + 4-path SGM over the whole disparity range, with the
//      left-right check and the uniqueness test;
//   2. at each finer level, only +-refine_radius_px around twice the coarser
//      disparity is searched, with box-aggregated census costs. The laser grid
//      period (~8 px) is far wider than that window, so the coarse level
//      decides which line is which and the fine level cannot jump a period;
//   3. sub-pixel: an equiangular fit of the cost, then a gain/offset
//      Lucas-Kanade fit on the intensities (subpixel_refine.h), which removes
//      the cost fit's peak-locking bias;
//   4. filters: ZNCC and texture thresholds, consistency with the local
//      disparity plane, speckle removal (connected components of similar
//      disparity smaller than speckle_window_px), range; after the line
//      index and growing, the pixels the right camera cannot see
//      (right_occlusion.h).
// MatcherKind::kOpenCvSgbm3Way runs OpenCV's StereoSGBM (MODE_SGBM_3WAY) on
// the same region and the full range in place of steps 1-2, then the same
// steps 3-4: a baseline differing from ours in the integer matching only.
// MatcherKind::kOpenCvSgbm3WayStandalone is StereoSGBM as OpenCV users run
// it: its own 1/16 px sub-pixel fit, uniqueness, left-right check and
// speckle filter, none of ours: the baseline whose whole correspondence
// stage (filtering and sub-pixel included, as `stereorig match` defines it)
// is OpenCV's. The bench reports both.
#pragma once

#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "reconstruct/census_sgm.h"
#include "reconstruct/disparity_state.h"
#include "reconstruct/grid_line_support.h"
#include "reconstruct/line_index.h"
#include "reconstruct/local_surface_fit.h"
#include "reconstruct/region_grow.h"
#include "reconstruct/subpixel_refine.h"

namespace stereorig {

enum class MatcherKind { kCensusSgm, kOpenCvSgbm3Way, kOpenCvSgbm3WayStandalone };
// "census_sgm" | "opencv_sgbm_3way" | "opencv_sgbm_3way_standalone"
MatcherKind ParseMatcherKind(const std::string& name, const std::string& where);
const char* MatcherKindName(MatcherKind kind);

struct MatchOptions {
  MatcherKind matcher = MatcherKind::kCensusSgm;  // default census_sgm
  int min_disparity_px = 0;                       // smallest disparity searched, px; default 0
  int num_disparities = 64;                       // disparities searched: [min, min + num), px; default 64
  cv::Rect roi;                                   // left-image region to match; empty = whole image; default empty
  int pyramid_levels =
      0;  // census_sgm: halvings before the full-range SGM; default 0 (1 is ~2x faster, fills less on steep flanks)
  // census_sgm: before the full-resolution search, a half-resolution SGM over
  // the whole range finds the band of disparities the scene occupies (its
  // clusters of matches, disparity_band.h, + range_margin_px); only that band is searched at full
  // resolution. Cost: ~1/8 of a full search, saving most of a deep volume's range.
  bool narrow_range = true;  // default true
  int range_margin_px = 12;  // default 12 px: 6 let period-shifted matches in on the cup's flank (rms 0.07 -> 0.12 mm)
  // census_sgm with narrow_range: the band pass's SGM paths, 3 (left, right,
  // top: one pass, no volume kept) or 4 (+bottom), independent of
  // sgm.num_paths (the full-resolution search's). Default 4.
  int band_sgm_paths = 4;
  // census_sgm with narrow_range: the band pass runs on every
  // band_row_step-th row of its half-resolution images (the rows averaged
  // down, INTER_AREA; columns stay at half resolution, so a grid period is
  // still ~4 px along the rows), its blob filter's window scaled by the
  // same factor. 1 or 2; 2 needs guided_radius_px 0 (the guide is built on
  // the half-resolution grid). Default 1.
  int band_row_step = 1;
  // census_sgm with narrow_range: the full-resolution SGM searches each pixel
  // only within +-guided_radius_px of twice the band pass's half-resolution
  // disparity there (sgm_guide.h, SgmMatchGuided), gaps filled from the
  // neighbours: a cost volume of 2r+1 disparities instead of the whole band.
  // 0 = search the whole band. Default 0 (off): on the simulator's seed 7
  // (truth rig) the guided search at 15 px let whole patches settle one grid
  // period off (ball bar module 1 std 0.10 -> 0.46 mm, plate module 1 0.12 ->
  // 0.20, sphere module 0 0.077 -> 0.099) and at 20 px the tuber's module 0
  // (0.075 -> 0.119); seed 1 (calibrated rig) lost the plate's module 1 at 12
  // and 15 px. The whole-band search had none of these. It saves ~20 ms of
  // SGM per module; turn it on only with a test of its own scenes. Session 6,
  // with the vernier and wrong-line drops: still (demo ball bar module 0 std
  // 0.069 -> 0.152 mm, seed 7 ball bar module 1 0.080 -> 0.455).
  int guided_radius_px = 0;
  int refine_radius_px = 2;          // census_sgm: fine-level search +-radius around 2x coarse; default 2
  int refine_half_window_px = 1;     // census_sgm: fine-level cost box half size; default 1 (3x3)
  int census_half_width_px = 2;      // census_sgm: census window half width (<= 4); default 2 (5 px: tolerates
                                     // foreshortening, cup fill 47% -> 73% vs 9 px)
  int census_half_height_px = 3;     // census_sgm: census window half height (<= 3); default 3 (7 px)
  SgmOptions sgm;                    // census_sgm: penalties, paths, uniqueness, left-right check
  bool intensity_refinement = true;  // census_sgm: Lucas-Kanade sub-pixel step; default true
  SubpixelOptions subpixel;          // its window and limits
  // census_sgm: do that fit densely, all pixels at once (dense_refine.h),
  // pixels where the dense model does not hold falling back to the
  // per-pixel fit; default false: on the demo scenes only ~18% of the
  // candidates pass the dense tests (speckle leaves each pixel's optimum
  // > converged_step_px from the shared warp), so the dense pass costs more
  // than it saves, and on a fronto-parallel synthetic plane it is less
  // precise (0.024 vs < 0.020 px rms). Ignored by the opencv_sgbm_3way
  // matchers and without intensity_refinement.
  bool subpixel_dense = false;
  // census_sgm, opencv_sgbm_3way, with intensity_refinement: the first
  // sub-pixel pass refines every subpixel_column_step-th column of the ROI
  // only; a pixel between takes the value interpolated along its row between
  // the refined pixels either side where both were accepted and agree with
  // the local slope (skipped_columns.h), else it is refined itself. Growing
  // and the line index are unchanged. 1 = every pixel; in [1, 4]; default 1:
  // step 2 saves 10.5 % of the cup's module instructions at unchanged
  // precision, but the line index's component decisions flip on 8 of the
  // 40 scored modules (docs/reconstruct-log.md, session 9).
  int subpixel_column_step = 1;
  double min_zncc = 0.8;  // reject matches whose refined window correlates less; default 0.8
  double max_plane_deviation_px =
      0.7;  // reject d farther than this from the local 9x9 disparity plane (0 = off); default 0.7
  // census_sgm: the refined match must beat the ZNCC grid_half_period_px
  // either side by this (RefineAcceptance, disparity_state.h; 0 = off);
  // default 0.4. Passive captures: set 0.
  double min_distinctness = 0.4;
  // The distinctness test's shift (and the grid-line test's and the right
  // view edge's reach), px: half the laser grid's period along the rows,
  // at most 4 (grid_period_options.h); default 4 (the default ~8 px period).
  double grid_half_period_px = 4;
  double min_texture_dn = 1.5;  // reject windows with a grey-level std below this; default 1.5 DN
  LineIndexOptions line_index;  // census_sgm: the component-wide grid-period test (line_index.h)
  GrowOptions grow;             // census_sgm: growing into the pixels SGM left empty (region_grow.h)
  // census_sgm, opencv_sgbm_3way: drop the pixels the right camera cannot
  // see, last but the surface fit, after the left view's edge test
  // (right_occlusion.h): occluded by a nearer surface, or matched
  // within this of a right column without data (`right_valid`). 0 = both
  // off; default 1 px.
  double occlusion_margin_px = 1;
  // census_sgm, opencv_sgbm_3way: right after that, drop the surfaces near
  // the right view's edge whose alternatives a grid period over fall off
  // the view, so that no test can tell whether they lie a period off, and
  // which continue nowhere outside that zone (right_view_edge.h, status
  // right_view_edge). Default on.
  bool right_view_edge_test = true;
  // census_sgm, opencv_sgbm_3way: then drop the points no laser line
  // supports: fewer than grid_line.min_ridge_px ridges of the grid in the
  // window around them (grid_line_support.h, status no_grid_line): matches
  // on ambient shading and on the object's outline beside the grid's
  // envelope. Off for passive captures (no grid). Default on.
  GridLineOptions grid_line;
  // census_sgm, opencv_sgbm_3way: last, each disparity replaced by a quadric
  // fitted to its neighbourhood where one explains it (local_surface_fit.h):
  // the speckle scatter of the disparities (~0.27 px) falls by ~35%, detail
  // finer than the window (~4 x 2 mm at 200 mm) is smoothed. Default on.
  SurfaceFitOptions surface_fit;
  // CV_8UC1 of the right image's size: 0 where the rectified right image
  // has no data (ViewValidMask); empty = every column valid. The
  // runtime sets it from its remap tables. Default empty.
  cv::Mat right_valid;
  // census_sgm, opencv_sgbm_3way: CV_8UC1 of the left image's size, 0 where
  // the rectified left image has no data (ViewValidMask of the left remap
  // tables). Last but the surface fit, a point whose sub-pixel window
  // (subpixel.half_width_px x half_height_px about it) reaches such a pixel
  // is dropped (left_view_edge.h). Empty = no test. The runtime sets it.
  // Default empty.
  cv::Mat left_valid;
  int speckle_window_px = 100;    // remove disparity blobs smaller than this, px (0 = off); default 100
  double speckle_range_px = 1.0;  // neighbours within this disparity are one blob, px; default 1
  // census_sgm, opencv_sgbm_3way: where both of two neighbours' local
  // planes step more than speckle_range_px per px the same way, take their
  // difference from that step (RemoveSpeckleBlobsAlongSlopes,
  // speckle_filter.h): a surface the left camera grazes, dd/dx < -1 (a
  // plate 60 degrees to a module), is then one blob instead of one-pixel
  // strips the filter removes. In both passes: the seeds' (before the line
  // index and growing) and the last one. Default false: on the default rig's
  // scenes it changes a few limbs' points, and the score gate's fresh
  // realizations read +0.010 mm std on one cup's module and -0.77 fill
  // points on one ball bar's (docs/reconstruct-log.md, "The oblique plate
  // (session 22)"), all from the seeds' pass.
  bool speckle_along_slopes = false;
  // The same in the last pass only, after growing (speckle_along_slopes
  // true: in both anyway). There the filter cut the grown steep flanks near
  // a silhouette (|dd/dx| > 1: the tuber's right flank) into strips and
  // removed them, points that pass every test at the truth disparity.
  // Default true: +0.21 fill points on average over the gate's 90 module
  // rows, none lower, std within +0.0004 mm; the seed-5 tuber 89.2 / 89.0 ->
  // 91.2 / 90.2 % (docs/reconstruct-log.md, "The last speckle pass along
  // the slopes (session 28)").
  bool final_speckle_along_slopes = true;
  int sgbm_block_size = 5;  // opencv_sgbm_3way: block size, px (odd); default 5
  int num_threads = 2;      // threads a row-parallel step may use (1 = the calling one only); default 2
  void Check() const;       // throws InputError naming the bad field
};

struct MatchResult {
  // CV_32FC1, the left image's size: disparity in px (x_right = x_left - d),
  // +inf where no valid match (outside the ROI included).
  cv::Mat disparity_px;
  // CV_32FC1, same size: confidence in [0, 1] (ZNCC of the refined window;
  // 1 without intensity_refinement), 0 where invalid.
  cv::Mat confidence;
  // CV_8UC1, same size: PixelStatus of each pixel (census_sgm; SGBM:
  // kPoint or kNoSgmMatch inside the ROI).
  cv::Mat status;
  // Wall time of the sub-steps, ms: census_sgm: "band" (the half-resolution
  // range pass), "sgm" (census + SGM + left-right/uniqueness), "subpixel"
  // (slopes + Lucas-Kanade + filters; "subpixel_dense" within it: the dense
  // fit), "speckle"; opencv_sgbm_3way: "sgbm"
  // in place of "band" and "sgm".
  std::map<std::string, double> times_ms;
  // The disparities searched at full resolution, [min, min + num) px:
  // census_sgm with narrow_range, the occupied band the half-resolution pass
  // found (or the whole range if it found none); otherwise the whole
  // options.min_disparity_px / num_disparities range.
  int searched_min_disparity_px = 0;
  int searched_num_disparities = 0;
  // The band the half-resolution pass found before range_margin_px was added:
  // [min, end) px, the edges of its kept 4 px bins (disparity_band.h), so
  // its matches lie within one bin of each edge; end <= min where it found
  // none (narrow_range off, pyramid_levels >= 1, the OpenCV matchers).
  // Matches reaching an end of the volume's range say the surface may go on
  // past it, or a copy of the grid whole periods off was matched
  // (ModuleReport::RangeEndsReached).
  int occupied_min_disparity_px = 0;
  int occupied_end_disparity_px = 0;
  // The local surface fit's window and misfit, if it ran (MatchOptions::surface_fit).
  std::optional<SurfaceFitSummary> surface_fit;
  // The line index's first pass: each kept or moved component's vernier
  // reading at its alignment (line_index.h), for the module's row drift
  // (row_drift.h). Empty without the line index.
  std::vector<VernierReading> vernier_readings;
};

// The sub-pixel step's acceptance tests (disparity_state.h) as the options
// set them: the matcher's and anything that re-judges its matches.
RefineAcceptance AcceptanceFor(const MatchOptions& options);

// The smallest images Match takes with `options`, and why ("its coarsest
// level ... must hold a census window of 5x7 px"). census_sgm matches first
// at a coarser resolution (the images halved pyramid_levels times, or the
// band pass's half columns and 1 / (2 band_row_step) rows), whose images
// must still hold one census window: smaller, no pixel there has a window
// in the image (and below one pixel OpenCV's resize aborted the process).
// The OpenCV matchers work at full resolution only: 1x1.
struct MinMatchImage {
  cv::Size size;
  std::string why;
};
MinMatchImage MinMatchImageSize(const MatchOptions& options);

// left, right: CV_8UC1, same size (at least MinMatchImageSize), rectified.
// Stateless and thread-safe.
MatchResult Match(const cv::Mat& left, const cv::Mat& right, const MatchOptions& options);

}  // namespace stereorig
