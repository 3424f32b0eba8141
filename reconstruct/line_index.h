// Which laser line is which: a component-wide test of the grid period.
//
// The laser grid is nearly periodic along the rectified rows: shifting a
// match by one horizontal period (~8 px) maps the near-vertical lines onto
// their neighbours exactly and moves the near-horizontal lines (turned 2.6
// degrees) by only p*sin(2.6 deg) ~ 0.36 px vertically. The census cost at
// integer disparities cannot tell that offset from the sub-pixel phase
// error of an integer shift, so SGM sometimes settles a whole surface patch
// one period off (3.5 mm at 200 mm): consistent with itself and with the
// left-right check. Measured on the simulator's ball bar, module 1: 98 % of
// its matches were one period off.
//
// The intensities do tell, through a vernier: refine a window tall enough
// to hold a near-horizontal line (9 rows) with a free row offset. At the
// true match it reads ~0; one period off, the near-horizontal lines sit
// p*sin(2.6 deg) ~ 0.36 px higher or lower, and the fit reads that. One
// pixel's reading is noisy (sd ~0.1-0.4 px with speckle); the mean over a
// component's sampled pixels is not. So: label the connected components of
// the disparity map (neighbours within 1 px), read each one's mean row
// offset at its alignment; if it is not conclusively ~0, read it at the
// best-correlating shift 2..max_shift_px either way too, fit the offset's
// step per period, and keep, move (re-refining every pixel) or, if the
// zero crossing is ambiguous, drop the component (ambiguity_sigmas). A
// component that reads off but whose better alignment cannot be read (near
// the right image's edge, the true line can lie outside it) is dropped
// (drop_row_offset_px). Where it is read: lattice_sampling.
#pragma once

#include <map>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "reconstruct/disparity_state.h"

namespace stereorig {

struct LineIndexOptions {
  bool enabled = true;        // default true
  int max_shift_px = 12;      // shifts tried: 2..max_shift_px either way, px; default 12 (> one ~8 px period)
  int min_component_px = 20;  // smaller components are left to the speckle filter; default 20 px
  // Pixels per component refined at each shift; default 48. With
  // lattice_sampling at least this many where the footprint holds as many
  // (48 to ~160 with the footprint's gap pixels), thinned to 2x at pitch <= 2.
  int samples = 48;
  int window_half_height_px = 4;        // the test window's half height, px; default 4 (9 rows: > one period)
  double max_row_offset_px = 0.1;       // a component whose mean row offset is within this is kept; default 0.1 px
  double min_row_offset_step_px = 0.1;  // the row offset must change by this per period to be read; default 0.1 px
  // A component that reads a row offset beyond this (and beyond 3 standard
  // errors) but cannot be moved, because the alignment the vernier points to
  // cannot be read (it lies outside the right image or no sample refines
  // there), is on the wrong line with the right one out of reach: its pixels
  // are dropped (PixelStatus::kWrongLine). 0 = off (kept, as before). Default
  // 0.15 px: the true alignment reads |offset| < 0.1 px on the simulator's
  // scenes (max_row_offset_px), one period off reads ~0.36 px (2.6 deg x 8 px).
  double drop_row_offset_px = 0.15;
  // The vernier is read over the component's footprint: its valid pixels
  // and the empty ones up to this far along the row from them (0 = the valid
  // pixels only, as before session 6). Default 8 px (one grid period: pixels
  // between the lines too). See Sample() in line_index.cc.
  int footprint_gap_px = 8;
  // A component whose reading from `samples` pixels is not conclusive
  // (not read as right, above) is read again over its whole footprint, one
  // sample per this many footprint pixels where that gives more, before it
  // is moved or dropped (0 = off; else >= 81). `samples` give a standard
  // error that does not shrink as a component grows (~0.05 px at speckle
  // 0.4: per-pixel sd ~0.37 px), so at strong speckle a large right
  // component can read 0.3-0.5 of an alignment off and be dropped whole
  // (simulator's sphere at speckle 0.4, module 1, an 18 400-pixel
  // component: -0.133 +- 0.051 px from 62 samples, -0.067 +- 0.023 from
  // 307). With lattice_sampling the re-read is the image's lattice of pitch
  // sqrt(area) = 9 px, the tall window's size: the samples' windows do not
  // overlap, so the standard error from their scatter holds (the speckle's
  // correlation length, ~8 x 5 px, is within a window). Without it, the
  // re-read is spread by raster rank and its windows can overlap: its
  // standard error is then an underestimate. By raster rank, components
  // read as right from `samples` are not re-read; on the lattice the whole
  // footprint is read from the start wherever this is on. The matcher uses
  // it only in modules where growing's noise-derived ZNCC floor bites
  // (GrowOptions::noise_zncc_factor, if on); with lattice sampling the demo
  // scores the same either way. Default 81.
  int area_per_sample_px = 81;
  // Where the vernier is read: on the image's lattice (FootprintSampler::
  // SampleLatticeAtLeast, at least `samples` pixels; the re-read above at
  // pitch sqrt(area_per_sample_px)) instead of by raster rank over the
  // component's footprint. Raster rank moves nearly every sample when a
  // component gains or loses a few pixels, so a component whose reading
  // lies near a decision's threshold was kept, moved or dropped whole by
  // chance: demo ball bar, module 1, fill 82.9 % at range_margin_px 12,
  // 72.8 % at 11 and 27.4 % at 13 (an 18 700-pixel component dropped); on
  // the lattice, 83.2-83.4 %. Default true; false = by raster rank, as
  // before session 10.
  bool lattice_sampling = true;
  // A component whose own reading is right (ambiguity_sigmas, below) is kept
  // without reading the other alignments. Not a YAML key: the matcher turns
  // it off, with lattice_sampling, where growing's noise floor bites (strong
  // speckle). There one period off reads only ~0.16-0.23 px against a
  // standard error of ~0.04, so a wrong component can pass that test: the
  // speckle-0.4 ball bar's module 1 kept one period off (std 1.3 mm) under 2
  // of 6 option controls, 0 of 6 with the alignments always read.
  bool quick_keep = true;
  // Threads for a component's fits (its samples at one shift, its pixels
  // when moved), summed in the samples' order: the same result on any
  // number. Not a YAML key: the matcher's num_threads.
  int num_threads = 1;
  // How sure the vernier must be, in standard errors of its reading. A
  // component is kept without reading the other alignments only if its
  // reading is within max_row_offset_px by this many standard errors; after
  // reading them, the zero crossing of the fitted row offset must lie this
  // many standard errors (of the crossing) inside half an alignment of the
  // nearest one, else the component is dropped (PixelStatus::kWrongLine).
  // 0 = off: kept within max(max_row_offset_px, 3 standard errors) and
  // moved to the nearest alignment whatever the margin (before session 6).
  // Default 1.
  double ambiguity_sigmas = 1.0;
  int max_seam_gap_px = 8;  // JoinAcrossPeriodJumps: widest gap of invalid pixels a seam may span; default 8 px
  int min_seam_px = 30;     // JoinAcrossPeriodJumps: shortest seam between two components it acts on; default 30 px
  // JoinAcrossPeriodJumps: a seam is a period jump (not a depth edge, whose
  // step varies along it) if at most a quarter of its differences lie
  // farther than this from their median (1 px before session 9). At speckle 0.4 the
  // differences of a plain period jump scatter wider (simulator's plate,
  // module 1: 10th-90th percentile -10.8 to -7.0 px around -9.2, half of
  // them beyond 1 px): 2 px (a quarter period) still tells one period from
  // none or two (the demo, seed 7 and speckle 0 score as with 1 px; speckle
  // 0.4 plate module 1: std 0.279 -> 0.143 mm, with the two options above).
  // Default 3 px since session 24: on a steep limb the differences also carry
  // the slopes extrapolated over the gap (seed 5's default-speckle ball bar,
  // module 1: a patch a period off, 34 % of its seam beyond 2 px; std 0.400
  // -> 0.076 mm at 3 px, no other row of the gate worse).
  double seam_spread_px = 3.0;
  void Check() const;  // throws InputError naming the bad field
};

// The connected components of the disparity map (LabelDisparityComponents
// at 1 px), handed from CorrectLineIndex to JoinAcrossPeriodJumps: labelling
// the whole map costs about as much as one component's vernier test, and
// the second run of both finds nothing to move on most captures.
struct DisparityComponents {
  cv::Mat labels;                        // CV_32SC1 of the image's size, -1 = none
  std::vector<std::vector<int>> pixels;  // per label, as y * cols + x
  bool matches_disparity = false;        // labels the disparity map as it is now
};

// What one component's vernier read at the alignment the test left it on
// (kept or moved to; dropped components give none): the mean row offset of
// its tall-window fits. On a well rectified pair every component reads ~0
// there; a module whose rows are off (a camera turned since calibration,
// the capture of another module) reads that offset, modulo the vernier's
// step per period (row_drift.h).
struct VernierReading {
  double row_offset_px = 0;
  double standard_error_px = 0;
  int fits = 0;    // successful fits the mean is over
  int pixels = 0;  // the component's valid pixels
};

// Revises `state` (disparity, confidence, status) inside `roi`. Returns the
// number of components moved (dropped ones not counted). left, right: CV_8UC1 rectified.
// components: if not null, receives the components it tested, marked as
// matching the map if it left the map unchanged.
// readings: if not null, receives a VernierReading per tested component
// that was kept or moved (appended).
int CorrectLineIndex(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const LineIndexOptions& options,
                     const RefineAcceptance& accept, DisparityState* state, DisparityComponents* components = nullptr,
                     std::vector<VernierReading>* readings = nullptr);

// Which line is which, by continuity: two components that meet along a seam
// with a jump of about one grid period (a smooth surface has none, and a
// depth edge's jump varies along it) cannot both be right. The one whose
// move leaves the size-weighted vernier reading over both nearer 0 is moved;
// if that is a tie, the smaller one.
// Run it after growing (the components then meet). Returns the number moved.
// components: if not null and matching the map (from CorrectLineIndex, same
// roi), used instead of labelling again; left marked as not matching.
int JoinAcrossPeriodJumps(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi,
                          const LineIndexOptions& options, const RefineAcceptance& accept, DisparityState* state,
                          DisparityComponents* components = nullptr);

// Connected components of the valid disparities in `roi` (4-neighbours whose
// disparities differ by <= max_step_px): CV_32SC1 label image (-1 = none),
// and the pixels of each component (as y * cols + x).
cv::Mat LabelDisparityComponents(const cv::Mat& disparity_px, const cv::Rect& roi, double max_step_px,
                                 std::vector<std::vector<int>>* components);

// The disparity differences across the seams between components (labels
// from LabelDisparityComponents, -1 = none) for JoinAcrossPeriodJumps: from
// each labelled pixel p to the next labelled pixel q along its row and
// along its column, if q is at most max_gap_px + 1 px on, inside `roi`, and
// of another label, d_q - (d_p + slope_p * step) with p's slope along that
// direction. Key (a, b), a < b: differences as d_b - d_a, in no particular
// order (the join takes their median and spread). All maps CV_32FC1 except
// labels (CV_32SC1), one size.
std::map<std::pair<int, int>, std::vector<float>> SeamDifferences(const cv::Mat& labels, const cv::Mat& disparity_px,
                                                                  const cv::Mat& slope_x, const cv::Mat& slope_y,
                                                                  const cv::Rect& roi, int max_gap_px);

}  // namespace stereorig
