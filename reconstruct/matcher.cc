#include "reconstruct/matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "calib/core/input_error.h"
#include "reconstruct/dense_refine.h"
#include "reconstruct/disparity_band.h"
#include "reconstruct/disparity_slopes.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/grid_line_support.h"
#include "reconstruct/left_view_edge.h"
#include "reconstruct/line_index.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/region_grow.h"
#include "reconstruct/right_occlusion.h"
#include "reconstruct/right_view_edge.h"
#include "reconstruct/sgm_guide.h"
#include "reconstruct/skipped_columns.h"
#include "reconstruct/speckle_filter.h"

namespace stereorig {

MatcherKind ParseMatcherKind(const std::string& name, const std::string& where) {
  if (name == "census_sgm") return MatcherKind::kCensusSgm;
  if (name == "opencv_sgbm_3way") return MatcherKind::kOpenCvSgbm3Way;
  if (name == "opencv_sgbm_3way_standalone") return MatcherKind::kOpenCvSgbm3WayStandalone;
  throw InputError(where,
                   "unknown matcher '" + name + "' (census_sgm, opencv_sgbm_3way or opencv_sgbm_3way_standalone)");
}

const char* MatcherKindName(MatcherKind kind) {
  switch (kind) {
    case MatcherKind::kCensusSgm:
      return "census_sgm";
    case MatcherKind::kOpenCvSgbm3Way:
      return "opencv_sgbm_3way";
    case MatcherKind::kOpenCvSgbm3WayStandalone:
      return "opencv_sgbm_3way_standalone";
  }
  return "?";
}

void MatchOptions::Check() const {
  if (num_disparities < 2 || num_disparities > 1024) throw InputError("num_disparities", "must be in [2, 1024]");
  if (min_disparity_px < -1024 || min_disparity_px > 2048)
    throw InputError("min_disparity", "must be in [-1024, 2048]");
  if (roi.width < 0 || roi.height < 0) throw InputError("roi", "must have a non-negative size");
  if (pyramid_levels < 0 || pyramid_levels > 3) throw InputError("pyramid_levels", "must be in [0, 3]");
  if (guided_radius_px < 0 || guided_radius_px > 64) throw InputError("guided_radius_px", "must be in [0, 64]");
  if (range_margin_px < 0 || range_margin_px > 256) throw InputError("range_margin_px", "must be in [0, 256] px");
  if (band_sgm_paths != 3 && band_sgm_paths != 4) throw InputError("band_sgm_paths", "must be 3 or 4");
  if (band_row_step < 1 || band_row_step > 2) throw InputError("band_row_step", "must be 1 or 2");
  if (band_row_step > 1 && guided_radius_px > 0)
    throw InputError("band_row_step", "must be 1 with guided_radius_px > 0 (the guide is half-resolution)");
  if (refine_radius_px < 1 || refine_radius_px > 8) throw InputError("refine_radius_px", "must be in [1, 8]");
  if (refine_half_window_px < 0 || refine_half_window_px > 5)
    throw InputError("refine_half_window_px", "must be in [0, 5]");
  if (census_half_width_px < 1 || census_half_width_px > 4)
    throw InputError("census_half_width_px", "must be in [1, 4]");
  if (census_half_height_px < 1 || census_half_height_px > 3)
    throw InputError("census_half_height_px", "must be in [1, 3]");
  sgm.Check();
  if (!(min_distinctness >= 0 && min_distinctness <= 2)) throw InputError("min_distinctness", "must be in [0, 2]");
  if (!(grid_half_period_px >= 1 && grid_half_period_px <= 32))
    throw InputError("grid_half_period_px", "must be in [1, 32]");
  subpixel.Check();
  line_index.Check();
  grow.Check();
  grid_line.Check();
  surface_fit.Check();
  if (subpixel_column_step < 1 || subpixel_column_step > 4)
    throw InputError("subpixel_column_step", "must be in [1, 4] (1 = every column)");
  if (!(min_zncc >= -1 && min_zncc < 1)) throw InputError("min_zncc", "must be in [-1, 1)");
  if (!(max_plane_deviation_px >= 0)) throw InputError("max_plane_deviation_px", "must be >= 0 (0 = off)");
  if (!(min_texture_dn >= 0)) throw InputError("min_texture_dn", "must be >= 0");
  if (speckle_window_px < 0) throw InputError("speckle_window_px", "must be >= 0 (0 = off)");
  if (!(speckle_range_px > 0)) throw InputError("speckle_range_px", "must be > 0");
  if (!(occlusion_margin_px >= 0 && occlusion_margin_px <= 8))
    throw InputError("occlusion_margin_px", "must be in [0, 8] (0 = off)");
  if (!right_valid.empty() && right_valid.type() != CV_8UC1) throw InputError("right_valid", "must be CV_8UC1");
  if (!left_valid.empty() && left_valid.type() != CV_8UC1) throw InputError("left_valid", "must be CV_8UC1");
  if (sgbm_block_size < 1 || sgbm_block_size % 2 == 0 || sgbm_block_size > 11)
    throw InputError("sgbm_block_size", "must be odd, in [1, 11]");
  if (num_threads < 1 || num_threads > 64) throw InputError("num_threads", "must be in [1, 64]");
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

cv::Rect ClampRoi(const cv::Rect& roi, const cv::Size& size) {
  if (roi.width == 0 || roi.height == 0) return cv::Rect(0, 0, size.width, size.height);
  return roi & cv::Rect(0, 0, size.width, size.height);
}

// Disparities of `region` at one pyramid level: CV_32FC1 of region.size(),
// NaN = invalid. Recurses to the coarser level first when levels_left > 0.
// guide_px (CV_16SC1 of region.size(), or empty): at the last level, search
// only +-o.guided_radius_px around it (SgmMatchGuided).
cv::Mat MatchLevel(const cv::Mat& left, const cv::Mat& right, const cv::Rect& region, int dmin, int num,
                   int levels_left, const MatchOptions& o, const cv::Mat& guide_px = cv::Mat()) {
  // Rows beyond the region too: the fine level's cost box reaches past it.
  // Only the columns the search reads: the region in the left image, the
  // region shifted by the disparity range in the right one.
  const int margin = o.refine_half_window_px;
  const int reach = levels_left > 0 ? o.refine_radius_px + 2 : 0;  // fine level: +-radius around 2x coarse
  const CensusImage cl =
      CensusTransform(left, region.y - margin, region.y + region.height + margin, o.num_threads, o.census_half_width_px,
                      o.census_half_height_px, region.x - margin, region.x + region.width + margin);
  const CensusImage cr = CensusTransform(
      right, region.y - margin, region.y + region.height + margin, o.num_threads, o.census_half_width_px,
      o.census_half_height_px, region.x - dmin - num - margin - reach, region.x + region.width - dmin + margin + reach);
  if (levels_left == 0 && !guide_px.empty())
    return SgmMatchGuided(cl, cr, region, guide_px, o.guided_radius_px, dmin, num, o.sgm);
  if (levels_left == 0) return SgmMatch(cl, cr, region, dmin, num, o.sgm);

  cv::Mat left_half, right_half;
  cv::resize(left, left_half, cv::Size(left.cols / 2, left.rows / 2), 0, 0, cv::INTER_AREA);
  cv::resize(right, right_half, cv::Size(right.cols / 2, right.rows / 2), 0, 0, cv::INTER_AREA);
  const int x0 = region.x / 2, y0 = region.y / 2;
  const int x1 = std::min(left_half.cols, (region.x + region.width + 1) / 2);
  const int y1 = std::min(left_half.rows, (region.y + region.height + 1) / 2);
  const cv::Rect half_region(x0, y0, std::max(1, x1 - x0), std::max(1, y1 - y0));
  // Coarse range covers the fine one; +1 so a fine disparity at the range's
  // top is not at the coarse edge (where SGM rejects it).
  const int half_min = int(std::floor(dmin / 2.0)) - 1;
  const int half_num = (num + 1) / 2 + 3;
  const cv::Mat coarse = MatchLevel(left_half, right_half, half_region, half_min, half_num, levels_left - 1, o);

  cv::Mat fine(region.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  const int r = o.refine_radius_px, bw = o.refine_half_window_px;
  const int ncand = 2 * r + 1;
  ParallelForChunks(region.height, o.num_threads, [&](int b, int e) {
    std::vector<int> costs(ncand);
    for (int yy = b; yy < e; ++yy) {
      const int y = region.y + yy;
      const int cy = std::min(y / 2 - y0, coarse.rows - 1);
      if (cy < 0) continue;
      float* out = fine.ptr<float>(yy);
      for (int xx = 0; xx < region.width; ++xx) {
        const int x = region.x + xx;
        const int cx = std::min(x / 2 - x0, coarse.cols - 1);
        if (cx < 0) continue;
        const float dc = coarse.at<float>(cy, cx);
        if (std::isnan(dc)) continue;
        const int centre = int(std::lround(2.0 * dc));
        if (y - bw < 0 || y + bw >= left.rows || x - bw < 0 || x + bw >= left.cols) continue;
        for (int k = 0; k < ncand; ++k) {
          const int d = centre - r + k;
          int c = 0;
          for (int v = -bw; v <= bw; ++v) {
            const uint64_t* lrow = cl.row(y + v);
            const uint64_t* rrow = cr.row(y + v);
            for (int u = -bw; u <= bw; ++u) {
              const int xr = x + u - d;
              c += (xr >= 0 && xr < cr.width) ? __builtin_popcountll(lrow[x + u] ^ rrow[xr]) : kCensusMaxCost;
            }
          }
          costs[k] = c;
        }
        const int best = int(std::min_element(costs.begin(), costs.end()) - costs.begin());
        if (best == 0 || best == ncand - 1) continue;  // the coarse level was off by more than r
        const double c0 = costs[best - 1], c1 = costs[best], c2 = costs[best + 1];
        const double slope = std::max(c0, c2) - c1;
        const double delta = slope > 0 ? 0.5 * (c0 - c2) / slope : 0.0;
        const double d = centre - r + best + delta;
        if (d < dmin || d > dmin + num - 1) continue;
        out[xx] = float(d);
      }
    }
  });
  return fine;
}

// Removes connected blobs of similar disparity smaller than the window, on a
// 1/16 px fixed-point copy (labelled as OpenCV's filterSpeckles would,
// speckle_filter.h).
// disparity_px may be a view (the ROI of a full-image map): it is written in
// place.
void RemoveSpeckles(cv::Mat disparity_px, const MatchOptions& o) {
  if (o.speckle_window_px <= 0) return;
  RemoveSpeckleBlobs(disparity_px, o.speckle_window_px, o.speckle_range_px);
}

// The same on the matcher's map within `roi`; along_slopes: neighbours
// compared along the local planes' slopes (RemoveSpeckleBlobsAlongSlopes):
// a surface sloping more than speckle_range_px per px is one blob, not
// strips.
void RemoveSpeckles(DisparityState* state, const cv::Rect& roi, const MatchOptions& o, bool along_slopes) {
  if (!along_slopes) return RemoveSpeckles(state->disparity_px(roi), o);
  if (o.speckle_window_px <= 0) return;
  RemoveSpeckleBlobsAlongSlopes(state->disparity_px(roi), state->slope_x(roi), state->slope_y(roi), o.speckle_window_px,
                                o.speckle_range_px);
}

// The band of disparities a half-resolution SGM finds in the ROI
// (disparity_band.h), within the given range. Returns false (keep the full
// range) if too few pixels matched. *guide_px: with o.guided_radius_px > 0
// and a band found, the guide of the full-resolution search over the ROI
// (GuideFromCoarse), else left empty. Sets `result`'s occupied band.
bool OccupiedBand(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const MatchOptions& o, int* dmin,
                  int* num, cv::Mat* guide_px, MatchResult* result) {
  const int ys = 2 * o.band_row_step;  // rows per band-pass row
  cv::Mat lh, rh;
  cv::resize(left, lh, cv::Size(left.cols / 2, left.rows / ys), 0, 0, cv::INTER_AREA);
  cv::resize(right, rh, cv::Size(right.cols / 2, right.rows / ys), 0, 0, cv::INTER_AREA);
  const cv::Rect half = cv::Rect(roi.x / 2, roi.y / ys, std::max(1, roi.width / 2), std::max(1, roi.height / ys)) &
                        cv::Rect(0, 0, lh.cols, lh.rows);
  MatchOptions band_options = o;
  band_options.sgm.num_paths = o.band_sgm_paths;
  cv::Mat d = MatchLevel(lh, rh, half, int(std::floor(*dmin / 2.0)) - 1, (*num + 1) / 2 + 3, 0, band_options);
  // The coarse level's mismatches are mostly small blobs: removing them
  // first leaves the band to the surfaces (disparity_band.h). The window is
  // an area: fewer rows, fewer pixels per blob.
  MatchOptions blobs = o;
  blobs.speckle_window_px = kCoarseSpeckleWindowPx / o.band_row_step;
  blobs.speckle_range_px = kCoarseSpeckleRangePx;
  RemoveSpeckles(d, blobs);
  std::vector<float> v;  // full-resolution px
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x)
      if (std::isfinite(d.at<float>(y, x))) v.push_back(2 * d.at<float>(y, x));
  const std::optional<DisparityBand> band = OccupiedDisparityBand(v, o.range_margin_px);
  if (!band) return false;
  result->occupied_min_disparity_px = band->min_px + o.range_margin_px;
  result->occupied_end_disparity_px = band->max_px - o.range_margin_px;
  const int new_min = std::max(*dmin, band->min_px), new_max = std::min(*dmin + *num - 1, band->max_px);
  if (new_max - new_min < 8) return false;
  *dmin = new_min;
  *num = new_max - new_min + 1;
  if (o.guided_radius_px > 0) *guide_px = GuideFromCoarse(d, half, roi, (new_min + new_max) / 2);
  return true;
}

// OpenCV StereoSGBM (MODE_SGBM_3WAY) over `roi` and the full range, in place
// of census SGM only: the filters and the sub-pixel step after it are the
// same as ours, so the baseline differs in the correspondence step alone.
// Here its own speckle filter is off (ours runs after), its uniqueness and
// left-right tolerance are ours; MatchOpenCvSgbm runs it with its own
// filters. Returns CV_32FC1 of roi.size(), NaN = invalid.
struct SgbmFilters {
  int uniqueness_percent = 0;
  int speckle_window_px = 0;  // 0 = SGBM's speckle filter off
  int speckle_range_px = 0;
};
cv::Mat SgbmRegion(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const MatchOptions& o,
                   const SgbmFilters& filters) {
  // SGBM needs the right image at the same column indices, so both images
  // are cut to the ROI widened on the left by the largest disparity; those
  // extra columns are the margin SGBM leaves invalid anyway.
  const int num16 = (o.num_disparities + 15) / 16 * 16;
  const int dmax = o.min_disparity_px + num16;
  const int x0 = std::max(0, roi.x - std::max(0, dmax));
  const int x1 = std::min(left.cols, roi.x + roi.width + std::max(0, -o.min_disparity_px));
  const cv::Rect cut(x0, roi.y, x1 - x0, roi.height);
  cv::Mat out(roi.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  // Where no column of the cut has its whole range inside the image, OpenCV
  // 4.6's SGBM returns before it allocates its buffers, and their
  // destructor then fails an assertion: a cv::Exception thrown from a
  // destructor, which ends the process (a rig whose range is wider than its
  // images: exit 134 where it should have found nothing). No pixel can be
  // matched then, so none is.
  if (cut.width <= std::max(dmax, 0) - std::min(o.min_disparity_px, 0)) return out;
  const int bs = o.sgbm_block_size;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      o.min_disparity_px, num16, bs, 8 * bs * bs, 32 * bs * bs, o.sgm.lr_max_diff_px, 63, filters.uniqueness_percent,
      filters.speckle_window_px, filters.speckle_range_px, cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat fixed;
  sgbm->compute(left(cut), right(cut), fixed);
  const double dmax_valid = o.min_disparity_px + o.num_disparities - 1;
  for (int y = 0; y < cut.height; ++y) {
    const int16_t* f = fixed.ptr<int16_t>(y);
    float* d = out.ptr<float>(y);
    for (int x = std::max(roi.x, x0); x < roi.x + roi.width; ++x) {
      const int16_t v = f[x - x0];
      if (v < o.min_disparity_px * 16) continue;  // SGBM's invalid marker
      const double disp = v / 16.0;
      if (disp <= dmax_valid) d[x - roi.x] = float(disp);
    }
  }
  return out;
}

MatchResult MatchRefineFilter(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const MatchOptions& o) {
  MatchResult result;
  auto t = std::chrono::steady_clock::now();
  auto lap = [&](const char* step) {
    const auto now = std::chrono::steady_clock::now();
    result.times_ms[step] = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
  };
  int dmin = o.min_disparity_px, num = o.num_disparities;
  const bool sgbm = o.matcher == MatcherKind::kOpenCvSgbm3Way;
  cv::Mat guide_px;
  if (!sgbm && o.narrow_range && o.pyramid_levels == 0)
    OccupiedBand(left, right, roi, o, &dmin, &num, &guide_px, &result);
  if (!sgbm) lap("band");
  result.searched_min_disparity_px = dmin;
  result.searched_num_disparities = num;
  const cv::Mat coarse_to_fine = sgbm ? SgbmRegion(left, right, roi, o, SgbmFilters{o.sgm.uniqueness_percent, 0, 0})
                                      : MatchLevel(left, right, roi, dmin, num, o.pyramid_levels, o, guide_px);
  lap(sgbm ? "sgbm" : "sgm");
  DisparityState state;
  state.disparity_px = cv::Mat(left.size(), CV_32FC1, cv::Scalar(kInf));
  state.confidence = cv::Mat(left.size(), CV_32FC1, cv::Scalar(0));
  state.status = cv::Mat(left.size(), CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kNotSearched)));
  state.slope_x = cv::Mat(left.size(), CV_32FC1, cv::Scalar(0));
  state.slope_y = cv::Mat(left.size(), CV_32FC1, cv::Scalar(0));
  const RefineAcceptance accept = AcceptanceFor(o);
  cv::Mat plane;
  cv::Mat slope_x_roi = state.slope_x(roi), slope_y_roi = state.slope_y(roi);
  DisparitySlopes(coarse_to_fine, &slope_x_roi, &slope_y_roi, &plane);
  DenseRefineResult dense;  // empty: every pixel takes the per-pixel fit
  if (!sgbm && o.intensity_refinement && o.subpixel_dense) {
    const auto t_dense = std::chrono::steady_clock::now();
    dense = DenseRefine(left, right, roi, coarse_to_fine, plane, slope_x_roi, slope_y_roi, o.subpixel, o.num_threads);
    result.times_ms["subpixel_dense"] = MsSince(t_dense);
  }
  const int column_step = o.intensity_refinement ? o.subpixel_column_step : 1;
  ParallelForChunks(roi.height, o.num_threads, [&](int b, int e) {
    for (int yy = b; yy < e; ++yy) {
      const int y = roi.y + yy;
      const float* in = coarse_to_fine.ptr<float>(yy);
      const float* slope_x = state.slope_x.ptr<float>(y);
      const float* slope_y = state.slope_y.ptr<float>(y);
      const float* plane_row = plane.ptr<float>(yy);
      float* out = state.disparity_px.ptr<float>(y);
      float* conf = state.confidence.ptr<float>(y);
      uint8_t* status = state.status.ptr<uint8_t>(y);
      // The tests before the refinement: kPoint = refine the pixel.
      auto before_refining = [&](int xx) {
        if (std::isnan(in[xx])) return PixelStatus::kNoSgmMatch;
        const float pl = plane_row[xx];
        if (o.max_plane_deviation_px > 0 && std::isnan(pl)) return PixelStatus::kNoPlane;
        // The plane test below, applied early to the cost-fit disparity (the
        // refinement moves it by < max_shift_px): saves refining mismatches.
        if (o.max_plane_deviation_px > 0 &&
            std::abs(double(in[xx]) - pl) > o.max_plane_deviation_px + o.subpixel.max_shift_px)
          return PixelStatus::kOffPlaneCoarse;
        return PixelStatus::kPoint;
      };
      // Consistency with the neighbourhood: the refined disparity must lie
      // within max_plane_deviation_px of the plane fitted to the 9x9
      // integer-level disparities around it (isolated mismatches and the
      // edges of mismatched patches fail this).
      auto on_plane = [&](int xx, double d) {
        return !(o.max_plane_deviation_px > 0 && std::abs(d - plane_row[xx]) > o.max_plane_deviation_px);
      };
      auto keep = [&](int x, double d, float confidence) {
        out[x] = float(d);
        conf[x] = confidence;
        status[x] = uint8_t(PixelStatus::kPoint);
      };
      // The refinement and the tests after it; sets the pixel's state.
      auto refine = [&](int xx) {
        const int x = roi.x + xx;
        double d = in[xx];
        float confidence = 1.0f;
        if (o.intensity_refinement) {
          SubpixelResult s = dense.ok.empty() ? SubpixelResult{} : dense.At(x, y);
          const PixelStatus why = s.ok ? Accept(left, right, x, y, slope_x[x], slope_y[x], s, accept)
                                       : RefineAndAccept(left, right, x, y, d, slope_x[x], slope_y[x], accept, &s);
          if (why != PixelStatus::kPoint) {
            status[x] = uint8_t(why);
            return;
          }
          d = s.disparity_px;
          confidence = float(std::clamp(s.zncc, 0.0, 1.0));
        } else if (d < accept.min_disparity_px || d > accept.max_disparity_px) {  // range filter
          status[x] = uint8_t(PixelStatus::kOutOfRange);
          return;
        }
        if (!on_plane(xx, d)) {
          status[x] = uint8_t(PixelStatus::kOffPlane);
          return;
        }
        keep(x, d, confidence);
      };
      // The refined columns first (all of them with column_step 1), then
      // the skipped ones from those either side (skipped_columns.h).
      for (int xx = 0; xx < roi.width; ++xx) {
        if (!IsRefinedColumn(xx, column_step)) continue;
        const PixelStatus why = before_refining(xx);
        if (why == PixelStatus::kPoint)
          refine(xx);
        else
          status[roi.x + xx] = uint8_t(why);
      }
      if (column_step == 1) continue;
      for (int xx = 0; xx < roi.width; ++xx) {
        if (IsRefinedColumn(xx, column_step)) continue;
        const int x = roi.x + xx;
        const PixelStatus why = before_refining(xx);
        if (why != PixelStatus::kPoint) {
          status[x] = uint8_t(why);
          continue;
        }
        const int x_left = x - xx % column_step, x_right = x_left + column_step;
        double d = 0;
        float confidence = 0;
        if (x_right < roi.x + roi.width &&
            InterpolateSkippedColumn(out, conf, status, x_left, x, x_right, slope_x[x], &d, &confidence) &&
            on_plane(xx, d))
          keep(x, d, confidence);
        else
          refine(xx);
      }
    }
  });
  lap("subpixel");
  // Seeds for the line-index test and growing: only the blobs the speckle
  // filter keeps (a small mismatched blob would otherwise grow into a large
  // wrong surface); the filter runs again on the grown map.
  RemoveSpeckles(&state, roi, o, o.speckle_along_slopes);  // outside the ROI nothing is valid
  if (o.intensity_refinement && (o.line_index.enabled || o.grow.enabled)) {
    // Growing's ZNCC floor, from the seeds' measured decorrelation (off by
    // default: the matcher's min_zncc). With it on, the vernier's whole-
    // footprint reading (line_index_area_per_sample_px) is used only where
    // the floor bites: there the views decorrelate strongly (speckle) and 48
    // samples leave large right components ambiguous; elsewhere they do not,
    // and a re-read only trades one noisy reading for another. There, too,
    // no component is kept before its other alignments are read
    // (LineIndexOptions::quick_keep).
    RefineAcceptance grow_accept = accept;
    grow_accept.min_zncc = GrowMinZncc(state.disparity_px, state.confidence, roi, o.grow, accept.min_zncc);
    LineIndexOptions line_index = o.line_index;
    line_index.num_threads = o.num_threads;
    const bool floor_bites = o.grow.noise_zncc_factor > 0 && grow_accept.min_zncc < accept.min_zncc;
    if (o.grow.noise_zncc_factor > 0 && !floor_bites) line_index.area_per_sample_px = 0;
    if (floor_bites && line_index.lattice_sampling) line_index.quick_keep = false;
    CorrectLineIndex(left, right, roi, line_index, accept, &state, nullptr, &result.vernier_readings);
    lap("line_index");
    // Shared by both passes: the second does not repeat the first's failed tries.
    std::optional<GrowMemory> grow_memory;
    if (o.grow.enabled) grow_memory.emplace(left, right, roi, o.grow);
    GrowDisparity(left, right, roi, o.grow, grow_accept, &state, grow_memory ? &*grow_memory : nullptr);
    lap("grow");
    // Grown components are larger, so their vernier reads better; a
    // component moved now leaves a gap that growing closes.
    // In this order (an operator's operands would be unsequenced): the
    // components are labelled once if the vernier test changes nothing.
    DisparityComponents components;
    int moved = 0;
    if (o.grow.enabled) {
      moved += CorrectLineIndex(left, right, roi, line_index, accept, &state, &components);
      moved += JoinAcrossPeriodJumps(left, right, roi, line_index, accept, &state, &components);
    }
    if (moved > 0) {
      lap("line_index_2");
      GrowDisparity(left, right, roi, o.grow, grow_accept, &state, &*grow_memory);
      lap("grow_2");
      // What the second growing added from the moved components is tested
      // too: growing can carry a wrong alignment along (speckle 0.4).
      if (o.line_index.ambiguity_sigmas > 0) {
        CorrectLineIndex(left, right, roi, line_index, accept, &state);
        lap("line_index_3");
      }
    } else {
      lap("line_index_2");
    }
    // The last pass: grown steep flanks are strips under the plain rule.
    RemoveSpeckles(&state, roi, o, o.speckle_along_slopes || o.final_speckle_along_slopes);
  }
  // The left view's edge first: its points are off by up to a few pixels,
  // and as occluders they would hide correct points next to them.
  DropLeftViewEdge(o.left_valid, o.subpixel.half_width_px, o.subpixel.half_height_px, roi, &state);
  const ViewGaps right_gaps(o.right_valid);
  DropRightInvisible(o.occlusion_margin_px, right_gaps, roi, &state, o.num_threads);
  // After it: the points it drops at the edge are no surface to continue.
  if (o.right_view_edge_test) DropUnverifiableAtRightViewEdge(right_gaps, accept, 1.0, roi, &state);
  DropWithoutGridLine(left, o.grid_line, int(std::ceil(o.grid_half_period_px)), roi, &state);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {  // outside the ROI: no point, confidence 0 already
    const float* d = state.disparity_px.ptr<float>(y);
    float* c = state.confidence.ptr<float>(y);
    uint8_t* status = state.status.ptr<uint8_t>(y);
    for (int x = roi.x; x < roi.x + roi.width; ++x)
      if (!std::isfinite(d[x])) {
        c[x] = 0;
        if (status[x] == uint8_t(PixelStatus::kPoint)) status[x] = uint8_t(PixelStatus::kSpeckle);
      }
  }
  lap("speckle");
  if (o.surface_fit.enabled) {
    result.surface_fit.emplace();
    FitLocalSurface(roi, o.surface_fit, o.num_threads, &state.disparity_px, &*result.surface_fit);
    lap("surface_fit");
  }
  result.disparity_px = state.disparity_px;
  result.confidence = state.confidence;
  result.status = state.status;
  return result;
}

MatchResult MatchOpenCvSgbm(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const MatchOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const cv::Mat d_roi = SgbmRegion(
      left, right, roi, o, SgbmFilters{10, o.speckle_window_px, std::max(1, int(std::lround(o.speckle_range_px)))});
  MatchResult result;
  result.times_ms["sgbm"] = MsSince(t0);
  result.searched_min_disparity_px = o.min_disparity_px;
  result.searched_num_disparities = o.num_disparities;
  result.disparity_px = cv::Mat(left.size(), CV_32FC1, cv::Scalar(kInf));
  result.confidence = cv::Mat(left.size(), CV_32FC1, cv::Scalar(0));
  result.status = cv::Mat(left.size(), CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kNotSearched)));
  result.status(roi).setTo(uint8_t(PixelStatus::kNoSgmMatch));
  for (int y = 0; y < roi.height; ++y) {
    const float* in = d_roi.ptr<float>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (std::isnan(in[x])) continue;
      result.disparity_px.at<float>(roi.y + y, roi.x + x) = in[x];
      result.confidence.at<float>(roi.y + y, roi.x + x) = 1.0f;
      result.status.at<uint8_t>(roi.y + y, roi.x + x) = uint8_t(PixelStatus::kPoint);
    }
  }
  return result;
}

}  // namespace

RefineAcceptance AcceptanceFor(const MatchOptions& o) {
  RefineAcceptance accept;
  accept.subpixel = o.subpixel;
  accept.min_zncc = o.min_zncc;
  accept.min_texture_dn = o.min_texture_dn;
  accept.min_disparity_px = o.min_disparity_px;
  accept.max_disparity_px = o.min_disparity_px + o.num_disparities - 1;
  accept.min_distinctness = o.min_distinctness;
  accept.half_period_px = o.grid_half_period_px;
  return accept;
}

MinMatchImage MinMatchImageSize(const MatchOptions& o) {
  if (o.matcher != MatcherKind::kCensusSgm) return {cv::Size(1, 1), "(it matches at full resolution only)"};
  const cv::Size window(2 * o.census_half_width_px + 1, 2 * o.census_half_height_px + 1);
  const std::string census = "a census window of " + std::to_string(window.width) + "x" +
                             std::to_string(window.height) + " px (census_half_width_px, census_half_height_px)";
  if (o.pyramid_levels > 0) {
    const int f = 1 << o.pyramid_levels;
    return {cv::Size(f * window.width, f * window.height),
            "with these options: its coarsest level, the images halved " + std::to_string(o.pyramid_levels) +
                " times (pyramid_levels), must hold " + census};
  }
  if (o.narrow_range) {
    const int fy = 2 * o.band_row_step;
    return {cv::Size(2 * window.width, fy * window.height),
            "with these options: the band pass's images, at half the columns and 1/" + std::to_string(fy) +
                " of the rows (narrow_range, band_row_step), must hold " + census};
  }
  return {window, "with these options: the images must hold " + census};
}

MatchResult Match(const cv::Mat& left, const cv::Mat& right, const MatchOptions& options) {
  options.Check();
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) throw InputError("match", "images must be 8-bit grey");
  if (left.size() != right.size()) throw InputError("match", "left and right images differ in size");
  if (const MinMatchImage min = MinMatchImageSize(options); left.cols < min.size.width || left.rows < min.size.height)
    throw InputError("match", "images of " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                                  " px are smaller than the " + std::to_string(min.size.width) + "x" +
                                  std::to_string(min.size.height) + " px the matcher needs " + min.why);
  if (!options.right_valid.empty() && options.right_valid.size() != right.size())
    throw InputError("right_valid", "differs in size from the right image");
  if (!options.left_valid.empty() && options.left_valid.size() != left.size())
    throw InputError("left_valid", "differs in size from the left image");
  const cv::Rect roi = ClampRoi(options.roi, left.size());
  if (roi.width <= 0 || roi.height <= 0) throw InputError("roi", "does not overlap the image");
  if (options.matcher == MatcherKind::kOpenCvSgbm3WayStandalone) return MatchOpenCvSgbm(left, right, roi, options);
  return MatchRefineFilter(left, right, roi, options);
}

}  // namespace stereorig
