// The dense sub-pixel fit (dense_refine.h) against the per-pixel one it
// replaces and against the rendered truth (synthetic_pair.h).
#include "reconstruct/dense_refine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

constexpr int kMargin = 12;  // px: windows and taps stay inside both images

// The fields a matcher hands the fit: a start scattered +-0.2 px about the
// truth (a cost fit's error), the local plane off by 0.1 px (a 9x9 plane of
// such starts), and the true slopes (+ slope_error_x on the right half).
struct Inputs {
  cv::Rect roi;
  cv::Mat start, plane, slope_x, slope_y;
};
Inputs MakeInputs(const SyntheticPair& pair, const SyntheticPairSpec& spec, double slope_error_x) {
  Inputs in;
  in.roi = cv::Rect(kMargin, kMargin, pair.left.cols - 2 * kMargin, pair.left.rows - 2 * kMargin);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> scatter(-0.2f, 0.2f);
  in.start = cv::Mat(in.roi.size(), CV_32FC1);
  in.plane = cv::Mat(in.roi.size(), CV_32FC1);
  in.slope_x = cv::Mat(in.roi.size(), CV_32FC1);
  in.slope_y = cv::Mat(in.roi.size(), CV_32FC1, cv::Scalar(spec.dv));
  for (int yy = 0; yy < in.roi.height; ++yy)
    for (int xx = 0; xx < in.roi.width; ++xx) {
      const double truth = pair.true_disparity_px.at<double>(in.roi.y + yy, in.roi.x + xx);
      in.start.at<float>(yy, xx) = float(truth) + scatter(rng);
      in.plane.at<float>(yy, xx) = float(truth + 0.1);
      in.slope_x.at<float>(yy, xx) = float(spec.du + (xx >= in.roi.width / 2 ? slope_error_x : 0.0));
    }
  return in;
}

DenseRefineResult RunDense(const SyntheticPair& pair, const Inputs& in, const SubpixelOptions& o) {
  return DenseRefine(pair.left, pair.right, in.roi, in.start, in.plane, in.slope_x, in.slope_y, o, 2);
}

TEST(DenseRefine, EqualsPerPixelFitOnSlantedPlane) {
  SyntheticPairSpec spec;  // 320x240, d = 40 + 0.04 x + 0.015 y, noise 2 DN
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const Inputs in = MakeInputs(pair, spec, 0.0);
  const SubpixelOptions o;
  const DenseRefineResult dense = RunDense(pair, in, o);
  double sum2 = 0, max_abs = 0, zncc_max = 0;
  int both = 0, per_pixel_ok = 0;
  for (int yy = 0; yy < in.roi.height; ++yy)
    for (int xx = 0; xx < in.roi.width; ++xx) {
      const int x = in.roi.x + xx, y = in.roi.y + yy;
      const SubpixelResult d = dense.At(x, y);
      const SubpixelResult p = RefineDisparity(pair.left, pair.right, x, y, in.start.at<float>(yy, xx),
                                               in.slope_x.at<float>(yy, xx), in.slope_y.at<float>(yy, xx), o);
      if (!p.ok) continue;  // e.g. the match leaves the right image
      ++per_pixel_ok;
      if (!d.ok) continue;
      const double e = d.disparity_px - p.disparity_px;
      sum2 += e * e, max_abs = std::max(max_abs, std::abs(e)), ++both;
      zncc_max = std::max(zncc_max, std::abs(d.zncc - p.zncc));
      EXPECT_EQ(d.std_dn, float(p.std_dn)) << x << "," << y;  // the same left window
    }
  const double rms = std::sqrt(sum2 / both);
  std::printf("dense %d of the %d per-pixel fits; dense - per-pixel: rms %.4f px, max %.4f px; |dzncc| max %.4f\n",
              both, per_pixel_ok, rms, max_abs, zncc_max);
  // On a plane with exact slopes the dense model holds nearly everywhere
  // (the last pass warps by the first pass's estimates, which scatter by
  // the fit's noise, ~0.015 px at 2 DN, well inside kMaxWarpDeviationPx).
  EXPECT_GT(both, 0.95 * per_pixel_ok);
  // The two fits differ by (a) the warp's deviation from each window's
  // plane: a weighted mean (weights g^2, concentrated on the ~third of the
  // window on laser lines) of deviations whose RMS is at most
  // kMaxWarpDeviationPx, so up to ~sqrt(3) times that at worst, and ~ the
  // fit noise (~0.02 px at 2 DN) divided by the window's ~3 independent
  // line crossings typically; (b) convergence: either stops after a step
  // < converged_step_px = 0.05 px, which leaves up to ~0.002 px
  // (subpixel_refine.h).
  EXPECT_LT(rms, 0.012);
  EXPECT_LT(max_abs, std::sqrt(3.0) * kMaxWarpDeviationPx);
  // The same sums, one pass apart in d: ZNCCs agree to far below the
  // acceptance threshold's scale.
  EXPECT_LT(zncc_max, 0.01);
}

TEST(DenseRefine, RecoversTruthWithoutPeakLocking) {
  SyntheticPairSpec spec;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const Inputs in = MakeInputs(pair, spec, 0.0);
  const DenseRefineResult dense = RunDense(pair, in, SubpixelOptions{});
  // Error binned by the true disparity's fractional part: a cost-curve fit
  // shows a ~0.05 px sawtooth here (matcher_test.cc); an intensity fit none.
  double bin_sum[10] = {}, sum = 0, sum2 = 0, per_pixel_sum2 = 0;
  int bin_n[10] = {}, n = 0, per_pixel_n = 0;
  for (int yy = 0; yy < in.roi.height; ++yy)
    for (int xx = 0; xx < in.roi.width; ++xx) {
      const int x = in.roi.x + xx, y = in.roi.y + yy;
      const SubpixelResult d = dense.At(x, y);
      if (!d.ok) continue;
      const double truth = pair.true_disparity_px.at<double>(y, x);
      const double e = d.disparity_px - truth;
      const SubpixelResult p =
          RefineDisparity(pair.left, pair.right, x, y, in.start.at<float>(yy, xx), in.slope_x.at<float>(yy, xx),
                          in.slope_y.at<float>(yy, xx), SubpixelOptions{});
      if (p.ok) per_pixel_sum2 += std::pow(p.disparity_px - truth, 2), ++per_pixel_n;
      const int bin = std::min(9, int((truth - std::floor(truth)) * 10));
      bin_sum[bin] += e, ++bin_n[bin];
      sum += e, sum2 += e * e, ++n;
    }
  const double mean = sum / n, rms = std::sqrt(sum2 / n), per_pixel_rms = std::sqrt(per_pixel_sum2 / per_pixel_n);
  std::printf("dense vs truth: n %d, mean %+.4f px, rms %.4f px (per-pixel fit %.4f); bins:", n, mean, rms,
              per_pixel_rms);
  double worst = 0;
  for (int i = 0; i < 10; ++i) {
    ASSERT_GT(bin_n[i], 1000);
    std::printf(" %+.4f", bin_sum[i] / bin_n[i]);
    worst = std::max(worst, std::abs(bin_sum[i] / bin_n[i] - mean));
  }
  std::printf("\n");
  // Noise: 2 DN on both images gives a CRLB of ~0.015 px rms per pixel for
  // this pair (matcher_test.cc's NoiseFloorRms); the slopes are exact, so no
  // model error: rms < 1.6x the CRLB (the fit also estimates gain and
  // offset), no worse than the per-pixel fit's beyond 5%, and no bias beyond
  // the Lanczos table's 0.002 px quantisation and 8-bit rounding.
  EXPECT_LT(rms, 0.024);
  EXPECT_LT(rms, 1.05 * per_pixel_rms);
  EXPECT_LT(std::abs(mean), 0.005);
  // Each bin holds > 1000 pixels, ~> 40 independent windows (a 9x3 window),
  // so a bin mean's standard error is ~0.015 / sqrt(40) = 0.0024 px: a flat
  // profile stays within 0.008 px (3.3 SE); peak locking would be ~0.05.
  EXPECT_LT(worst, 0.008);
}

TEST(DenseRefine, FallsBackWithoutAFieldAndFollowsTheFieldsOwnSlopes) {
  SyntheticPairSpec spec;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  // The right half's given slope is off by 0.03 px/px (DisparitySlopes' error
  // on a curved flank), and a 20x20 px block has no plane (too few SGM
  // matches around it).
  Inputs in = MakeInputs(pair, spec, 0.03);
  const cv::Rect hole(60, 100, 20, 20);  // roi coordinates
  in.plane(hole).setTo(std::numeric_limits<float>::quiet_NaN());
  const SubpixelOptions o;
  const DenseRefineResult dense = RunDense(pair, in, o);
  const int half = in.roi.width / 2, hw = o.half_width_px, hh = o.half_height_px;
  int near_hole = 0, near_hole_dense = 0, right_n = 0, right_dense = 0;
  double dense2 = 0, per_pixel2 = 0;
  int both = 0;
  for (int yy = hh; yy < in.roi.height - hh; ++yy)
    for (int xx = hw; xx < in.roi.width - hw; ++xx) {
      const int x = in.roi.x + xx, y = in.roi.y + yy;
      const double truth = pair.true_disparity_px.at<double>(y, x);
      if (x - truth < kMargin) continue;  // the match leaves the right image
      const bool ok = dense.ok.at<uint8_t>(yy, xx);
      // A window reaching into the hole has no warp there.
      if (xx >= hole.x - hw && xx < hole.x + hole.width + hw && yy >= hole.y - hh && yy < hole.y + hole.height + hh)
        near_hole_dense += ok, ++near_hole;
      if (xx < half + hw) continue;
      right_dense += ok, ++right_n;
      const SubpixelResult p = RefineDisparity(pair.left, pair.right, x, y, in.start.at<float>(yy, xx),
                                               in.slope_x.at<float>(yy, xx), in.slope_y.at<float>(yy, xx), o);
      if (!ok || !p.ok) continue;
      dense2 += std::pow(dense.disparity_px.at<float>(yy, xx) - truth, 2);
      per_pixel2 += std::pow(p.disparity_px - truth, 2), ++both;
    }
  const double dense_rms = std::sqrt(dense2 / both), per_pixel_rms = std::sqrt(per_pixel2 / both);
  std::printf("near the hole %d/%d dense; right half %d/%d dense, rms vs truth %.4f px (per-pixel fit %.4f)\n",
              near_hole_dense, near_hole, right_dense, right_n, dense_rms, per_pixel_rms);
  EXPECT_EQ(near_hole_dense, 0);
  EXPECT_GT(near_hole, 500);
  // The wrong slopes do not send the right half back: the warp follows the
  // field, whose slopes are the true ones.
  EXPECT_GT(right_dense, 0.9 * right_n);
  // And the dense fit is the better one there: the per-pixel model is off by
  // 0.03 px/px, which alone costs ~0.02 px rms on this grid (0.027 px at
  // 0.04 px/px, matcher_test.cc); the dense fit keeps the noise floor
  // (~0.016 px, test above).
  EXPECT_LT(dense_rms, 0.02);
  EXPECT_LT(dense_rms, per_pixel_rms);
}

}  // namespace
}  // namespace stereorig
