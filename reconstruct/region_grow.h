// Growing the disparity map from its accepted matches into the pixels SGM
// left empty.
//
// Most of the fill lost on curved objects is lost in SGM's left-right and
// uniqueness tests (measured on the simulator's scenes: 5-30 % of the target
// pixels), and mostly for the same reason: the laser grid is nearly periodic
// along the rows, so a pixel whose census costs one grid period apart are
// within the uniqueness margin is rejected although its neighbours already
// say which line it is on. Growing resolves that from continuity: a pixel
// next to an accepted match is predicted from the plane through the accepted
// disparities around it (7x7), refined by Lucas-Kanade
// (subpixel_refine.h) and accepted if the refinement passes the matcher's
// own tests (ZNCC, texture, range) and stays within max_deviation_px of the
// prediction; then its neighbours are tried, breadth first. A depth edge or
// an occlusion stops it (the prediction no longer correlates), and so does
// the end of the lit surface (no grid: RefineAcceptance::min_distinctness).
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"
#include "reconstruct/oblique_refine.h"

namespace stereorig {

struct GrowOptions {
  bool enabled = true;            // default true
  int max_tries = 2;              // attempts per pixel, from different accepted neighbours; default 2
  int plane_radius_px = 3;        // the prediction: plane through the valid pixels within this, px; default 3 (7x7)
  double max_deviation_px = 0.5;  // refined minus predicted disparity, px; default 0.5 (well below a ~8 px period)
  // Where the centred refinement fails, the window shifted by a half width
  // towards the neighbour grown from (shifted_window.h: pixels at a
  // silhouette), on surfaces whose foreshortening 1 - dd/dx lies within
  // [shifted_min_foreshortening, 1 / shifted_min_foreshortening] (at a limb
  // the plane that carries the result to the pixel bends away).
  // Default true, with the shifted window's ZNCC held to 0.95: on the demo
  // and seed 7 it fills 0.5-3 points more on every scene (tuber 89.5 -> 90-91 %,
  // ball bar 79.5 -> 82 %) for at most +0.006 mm of per-module std. At 0.9
  // it filled more (ball bar 85 %) but admitted wrong windows at
  // silhouettes: std over 0.1 mm on the ball bar and plate
  // (docs/reconstruct-log.md).
  bool shifted_windows = true;
  double shifted_min_foreshortening = 0.5;  // default 0.5
  double shifted_min_zncc = 0.95;           // the shifted window's ZNCC must reach this too; default 0.95
  // The same for a pixel in a hole of the matched surface, not at its edge:
  // grown along the row, with a valid pixel on the far side within the
  // window's half width (region_grow.cc, Enclosed). The matcher's min_zncc
  // is the floor. Default 0.8 (= min_zncc): such a pixel is lost to speckle
  // spoiling part of its centred window, and the shifted window sees only
  // the surface around it; the wrong windows that 0.95 keeps out lie at
  // silhouettes and the lit region's end, where the far side is background.
  // Demo and seed 7: +0.4-0.9 fill points on every scene, per-module std
  // within +0.005 mm (docs/reconstruct-log.md, session 6).
  double shifted_enclosed_min_zncc = 0.8;
  // Growing's ZNCC floor from the measured noise (GrowMinZncc; 0 = off:
  // the matcher's min_zncc). A window's ZNCC at its true match is about
  // S / (S + N), S the grid's variance in it and N the part of the two
  // views that does not correlate (laser speckle, sensor noise), so 1 - ZNCC
  // ~ N / (S + N) and the disparity's scatter grows as sqrt(1 - ZNCC). The
  // module's typical decorrelation is the median 1 - ZNCC of the seeds (the
  // matches growing starts from); a grown pixel, whose alignment its
  // neighbours' plane already fixes (within max_deviation_px, far below a
  // period), is accepted if its 1 - ZNCC is at most this times that, i.e. its
  // scatter at most sqrt(this) times the typical one. The floor never rises
  // above the matcher's min_zncc and never falls below noise_min_zncc.
  // Demo (speckle 0.2): seeds' median ZNCC ~0.97, 1 - 4 x 0.03 > 0.8, so
  // nothing changes (all 30 module rows of the demo, seed 7 and speckle 0
  // score as before); speckle 0.4: median ~0.925, floor ~0.7, +3 to +32 fill
  // points per module (docs/reconstruct-log.md, "Strong speckle (session 9)").
  // Default 4.
  double noise_zncc_factor = 4;
  double noise_min_zncc = 0.6;  // the noise-derived floor's lowest value; default 0.6
  // Where it still fails on a strongly foreshortened surface, the views
  // matched in resolution (oblique_refine.h; on by default: +0.3-0.6 fill
  // points on every curved scene, accuracy unchanged).
  ObliqueOptions oblique;
  void Check() const;  // throws InputError naming the bad field
};

// The ZNCC growing accepts (GrowOptions::noise_zncc_factor): min_zncc if the
// factor is 0 or no pixel of `roi` holds a disparity, else
// clamp(1 - factor * median(1 - confidence), noise_min_zncc, min_zncc) over
// the pixels of `roi` with a finite disparity (their confidence = the
// refined window's ZNCC). disparity_px, confidence: CV_32FC1, same size.
double GrowMinZncc(const cv::Mat& disparity_px, const cv::Mat& confidence, const cv::Rect& roi, const GrowOptions& o,
                   double min_zncc);

// What growing keeps between its passes over one capture (the matcher
// grows, moves components to other lines, and grows again): the oblique
// views (blurred on first use), and every failed try. A try's outcome
// depends only on its start disparity and slopes (and, with shifted
// windows, the side it is grown from and whether the far side holds a
// disparity): a pixel predicted exactly as in any of its earlier failed
// tries would fail again the same way, so it is not refined again, only
// given that try's status (on the demo plate's second pass 1810 of 6284
// tries are such repeats; keeping only the last failed try per pixel
// caught 1288). The result is the same as without it.
class GrowMemory {
 public:
  // For GrowDisparity over `roi` of this pair with these options only.
  GrowMemory(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const GrowOptions& options);

 private:
  friend int GrowDisparity(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const GrowOptions& options,
                           const RefineAcceptance& accept, DisparityState* state, GrowMemory* memory);
  struct FailedTry {
    double start_px = 0, slope_x = 0, slope_y = 0;  // the prediction tried
    int32_t previous = 0;                           // the pixel's earlier failed try: index + 1 in failed_, 0 = none
    int8_t from_dx = 0, from_dy = 0;                // the neighbour grown from, relative to the pixel
    uint8_t status = 0;                             // PixelStatus it failed with
    bool enclosed = false;                          // it was in a hole (region_grow.cc, Enclosed)
  };
  cv::Rect roi_;
  ObliqueViews oblique_;
  // Per pixel of roi_, row-major: its latest failed try, index + 1 in
  // failed_, 0 = none. (A few % of the pixels fail: 4 bytes each here and
  // the tries apart, rather than a try's 32 bytes for every pixel.)
  std::vector<int32_t> latest_failed_;
  std::vector<FailedTry> failed_;
};

// Grows `state` inside `roi`. Returns the number of pixels added.
// memory: shared by the passes over one capture (same left, right, roi,
// options and accept), or null (each call keeps its own).
int GrowDisparity(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const GrowOptions& options,
                  const RefineAcceptance& accept, DisparityState* state, GrowMemory* memory = nullptr);

}  // namespace stereorig
