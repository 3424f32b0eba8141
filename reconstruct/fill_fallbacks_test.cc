// The growing fallbacks (shifted_window.h, oblique_refine.h) against the
// analytic truth of synthetic_pair.h: each recovers pixels the centred
// refinement loses, and what it recovers lies on the true disparity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "reconstruct/oblique_refine.h"
#include "reconstruct/shifted_window.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

RefineAcceptance Acceptance() {
  RefineAcceptance a;  // the matcher's defaults: 9x3 window, ZNCC 0.8, distinctness 0.4
  a.min_disparity_px = 0;
  a.max_disparity_px = 1000;
  return a;
}

// A plane that ends at column `edge` of the left image against a dark, flat
// background (the object's silhouette): the left pixels beyond the edge, and
// the right pixels beyond its match, are set to the background level.
TEST(ShiftedWindow, RecoversThePixelsAtASilhouetteOnTheTrueDisparity) {
  SyntheticPairSpec spec;  // d = 40 + 0.04 x + 0.015 y, noise 2 DN
  SyntheticPair pair = RenderSyntheticPair(spec);
  constexpr int kEdge = 200;
  constexpr uint8_t kBackground = 12;
  EndPlaneAtColumn(kEdge, kBackground, &pair);
  const RefineAcceptance accept = Acceptance();
  int centred_ok = 0, shifted_ok = 0, n = 0;
  double worst = 0, sum2 = 0;
  for (int y = 20; y < 220; ++y)
    for (int x = kEdge - 3; x < kEdge; ++x) {  // the window's last 3 columns reach the background
      ++n;
      const double truth = pair.true_disparity_px.at<double>(y, x);
      // Start as growing does: from the neighbours' plane, here the truth
      // plus a typical 0.2 px prediction error.
      const double predicted = truth + 0.2;
      const SubpixelResult c =
          RefineDisparity(pair.left, pair.right, x, y, predicted, spec.du, spec.dv, accept.subpixel);
      centred_ok += Accept(pair.left, pair.right, x, y, spec.du, spec.dv, c, accept) == PixelStatus::kPoint &&
                    std::abs(c.disparity_px - truth) < 0.1;
      SubpixelResult s;
      if (RefineShiftedWindow(pair.left, pair.right, x, y, cv::Point(-1, 0), predicted, spec.du, spec.dv, accept, 0.5,
                              &s) == PixelStatus::kPoint) {
        ++shifted_ok;
        worst = std::max(worst, std::abs(s.disparity_px - truth));
        sum2 += std::pow(s.disparity_px - truth, 2);
      }
    }
  std::printf("silhouette: centred %d, shifted %d of %d; shifted worst |e| %.3f px, rms %.3f px\n", centred_ok,
              shifted_ok, n, worst, std::sqrt(sum2 / std::max(1, shifted_ok)));
  EXPECT_GT(shifted_ok, 0.95 * n);
  EXPECT_GT(shifted_ok, centred_ok + n / 2);
  // The shifted window sees only the plane: its error is the noise of a 9x3
  // fit at 2 DN (matcher_test.cc: ~0.015 px rms on a full grid; more where
  // the window holds fewer lines), so rms 0.05 and worst 0.25 px over 600
  // pixels; a fit pulled by the edge would be off by a large part of a pixel.
  EXPECT_LT(std::sqrt(sum2 / std::max(1, shifted_ok)), 0.05);
  EXPECT_LT(worst, 0.25);
}

// A plane slanted so that the right camera sees it 2.5x compressed along the
// rows (1 - dd/dx = 0.4) and the reverse (2.5x stretched), seen through the
// simulator's optics (a Gaussian PSF of 0.6 px on both images, applied after
// the renderer's noise: it also smooths that noise a little).
struct Recovery {
  int n = 0, plain_ok = 0, oblique_ok = 0;
  int rescued = 0;                        // rejected by the plain refinement, accepted by the oblique one
  double plain_rms = 0, oblique_rms = 0;  // over the pixels each accepts, px
};
Recovery SteepSlopeRecovery(double du) {
  SyntheticPairSpec spec;
  spec.width = 480;
  spec.du = du;
  spec.dv = 0.0;
  spec.d0_px = du > 0 ? 10.0 : 650.0;
  spec.grid_sigma_px = 0.9;  // lines as the simulator's
  SyntheticPair pair = RenderSyntheticPair(spec);
  cv::GaussianBlur(pair.left, pair.left, cv::Size(5, 5), 0.6);
  cv::GaussianBlur(pair.right, pair.right, cv::Size(5, 5), 0.6);
  const RefineAcceptance accept = Acceptance();
  const ObliqueViews views(pair.left, pair.right, 0, pair.left.rows, ObliqueOptions{});  // PSF + pixel: 0.7 px
  Recovery out;
  for (int y = 20; y < 220; y += 2)
    for (int x = 60; x < 420; x += 3) {
      const double truth = pair.true_disparity_px.at<double>(y, x);
      if (x - truth < 40 || x - truth > pair.right.cols - 40) continue;
      ++out.n;
      const double start = truth + 0.2;
      const SubpixelResult p = RefineDisparity(pair.left, pair.right, x, y, start, du, 0.0, accept.subpixel);
      const bool plain = Accept(pair.left, pair.right, x, y, du, 0.0, p, accept) == PixelStatus::kPoint;
      if (plain) {
        ++out.plain_ok;
        out.plain_rms += std::pow(p.disparity_px - truth, 2);
      }
      SubpixelResult r;
      PixelStatus why;
      EXPECT_TRUE(views.Refine(x, y, start, du, 0.0, accept, &r, &why));
      if (why == PixelStatus::kPoint) {
        ++out.oblique_ok;
        out.rescued += !plain;
        out.oblique_rms += std::pow(r.disparity_px - truth, 2);
      }
    }
  out.plain_rms = std::sqrt(out.plain_rms / std::max(1, out.plain_ok));
  out.oblique_rms = std::sqrt(out.oblique_rms / std::max(1, out.oblique_ok));
  return out;
}

TEST(ObliqueRefine, MatchesStronglyForeshortenedSurfacesOnTheTrueDisparity) {
  for (const double du : {0.6, -1.5}) {
    const Recovery r = SteepSlopeRecovery(du);
    std::printf(
        "dd/dx %.1f: of %d, plain accepts %d (rms %.3f px), oblique %d (rms %.3f px), %d of them rejected by "
        "the plain one\n",
        du, r.n, r.plain_ok, r.plain_rms, r.oblique_ok, r.oblique_rms, r.rescued);
    ASSERT_GT(r.n, 1000);
    // As growing uses it, a fallback: where the right view is compressed
    // (the plain refinement's 9 px left window covers 3.6 right px) it must
    // add pixels the plain refinement rejects; where it is stretched, this
    // noise-free-PSF pair leaves the plain one nothing to lose (it accepts
    // all), and the oblique one must not lose them either ...
    if (du > 0)
      EXPECT_GT(r.rescued, r.n / 50);
    else
      EXPECT_GE(r.oblique_ok, r.plain_ok * 0.95);
    // ... and be more precise where it accepts: the views at one resolution
    // fit the window model, the plain refinement's sharper view does not.
    EXPECT_LT(r.oblique_rms, r.plain_rms);
  }
}

// ObliqueViews blurs its views lazily, tile by tile, as pixels ask. That
// cache must not change any result: each refinement, asked in a scattered
// order over both kinds of level (left view blurred where 1 - dd/dx < 0.7,
// right view where > 1.43), must equal the refinement on the views blurred
// whole, as the fallback is defined (oblique_refine.h: the sharper view
// low-passed along the rows by sigma_psf * sqrt(k^2 - 1)), and those must
// lie on the true disparity (as SteepSlopeRecovery's rms: < 0.1 px).
TEST(ObliqueRefine, LazyBlurringGivesTheResultsOfWholeViews) {
  for (const double du : {0.6, -1.5}) {
    SyntheticPairSpec spec;
    spec.width = 480;
    spec.du = du;
    spec.dv = 0.0;
    spec.d0_px = du > 0 ? 10.0 : 650.0;
    spec.grid_sigma_px = 0.9;
    SyntheticPair pair = RenderSyntheticPair(spec);
    cv::GaussianBlur(pair.left, pair.left, cv::Size(5, 5), 0.6);
    cv::GaussianBlur(pair.right, pair.right, cv::Size(5, 5), 0.6);
    const ObliqueOptions options;
    const double s = 1 - du;
    // The levels nearest s = 0.4 and 2.5 (oblique_refine.cc): 0.35 and 2.8.
    const double level = s < 1 ? 0.35 : 2.8, kl = s < 1 ? 1 / level : level;
    const double level_sigma = options.psf_sigma_px * std::sqrt(kl * kl - 1);
    const int radius = int(std::ceil(3 * level_sigma));
    cv::Mat whole_left = pair.left.clone(), whole_right = pair.right.clone();
    cv::Mat& sharp = s < 1 ? whole_left : whole_right;
    cv::sepFilter2D(s < 1 ? pair.left : pair.right, sharp, CV_8U,
                    cv::getGaussianKernel(2 * radius + 1, level_sigma, CV_32F), cv::Mat::ones(1, 1, CV_32F),
                    cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    RefineAcceptance accept = Acceptance();
    if (s < 1) accept.subpixel.half_width_px = std::clamp(int(std::lround(4 / s)), 4, options.max_half_width_px);
    const ObliqueViews views(pair.left, pair.right, 0, pair.left.rows, options);
    cv::RNG rng(7);
    int n = 0, accepted = 0;
    double sum2 = 0;
    for (int i = 0; i < 3000; ++i) {
      const int x = rng.uniform(0, pair.left.cols), y = rng.uniform(0, pair.left.rows);
      const double truth = pair.true_disparity_px.at<double>(y, x), start = truth + 0.2;
      SubpixelResult lazy;
      PixelStatus lazy_why;
      ASSERT_TRUE(views.Refine(x, y, start, du, 0.0, Acceptance(), &lazy, &lazy_why));
      const SubpixelResult whole = RefineDisparity(whole_left, whole_right, x, y, start, du, 0.0, accept.subpixel);
      const PixelStatus whole_why = Accept(whole_left, whole_right, x, y, du, 0.0, whole, accept);
      ASSERT_EQ(lazy.ok, whole.ok) << x << "," << y;
      ASSERT_EQ(lazy.disparity_px, whole.disparity_px) << x << "," << y;
      ASSERT_EQ(lazy.zncc, whole.zncc) << x << "," << y;
      ASSERT_EQ(lazy_why, whole_why) << x << "," << y;
      ++n;
      if (lazy_why == PixelStatus::kPoint) {
        ++accepted;
        sum2 += std::pow(lazy.disparity_px - truth, 2);
      }
    }
    std::printf("dd/dx %.1f: %d of %d accepted, rms %.3f px\n", du, accepted, n,
                std::sqrt(sum2 / std::max(1, accepted)));
    EXPECT_GT(accepted, n / 10);
    EXPECT_LT(std::sqrt(sum2 / std::max(1, accepted)), 0.1);
  }
}

}  // namespace
}  // namespace stereorig
