// The Lucas-Kanade fit's predicted disparity sigma (SubpixelResult::
// disparity_sigma_px) against the scatter it predicts: an analytically
// rendered pair (synthetic_pair.h) with white Gaussian noise of a known level
// added here, refined at pixels whose windows (and Lanczos taps) do not
// overlap, so the errors are independent samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "reconstruct/subpixel_refine.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

struct Sample {
  double error_px, predicted_variance_px2;
  double key;  // the predicted variance of the same window under another noise draw (for sorting)
};

// image + N(0, sigma^2) per pixel, rounded to 8 bits.
cv::Mat AddNoise(const cv::Mat& image, double sigma_dn, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, sigma_dn);
  cv::Mat out(image.size(), CV_8UC1);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      out.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(std::lround(image.at<uint8_t>(y, x) + noise(rng)));
  return out;
}

// Refines a grid of pixels 14 px apart along the rows and 4 px apart across
// them (a 9 x 3 window plus 3 Lanczos taps either side: no pixel is shared),
// started 0.3 px off the truth, with the true slopes, on the pair (left,
// right); `other_*`: the same pair under an independent noise draw.
std::vector<Sample> RefineGrid(const cv::Mat& left, const cv::Mat& right, const cv::Mat& other_left,
                               const cv::Mat& other_right, const SyntheticPair& pair, const SyntheticPairSpec& spec) {
  const SubpixelOptions options;
  std::vector<Sample> samples;
  for (int y = 4; y + 4 < left.rows; y += 4)
    for (int x = 70; x + 10 < left.cols; x += 14) {
      const double truth = pair.true_disparity_px.at<double>(y, x);
      const SubpixelResult r = RefineDisparity(left, right, x, y, truth + 0.3, spec.du, spec.dv, options);
      const SubpixelResult k = RefineDisparity(other_left, other_right, x, y, truth + 0.3, spec.du, spec.dv, options);
      if (!r.ok || !k.ok) continue;
      samples.push_back({r.disparity_px - truth, r.disparity_sigma_px * r.disparity_sigma_px,
                         k.disparity_sigma_px * k.disparity_sigma_px});
    }
  return samples;
}

// Mean squared error over mean predicted variance. The predicted variance
// is the residual variance e'e/(n-3) (unbiased) times (J'J)^-1, so its mean,
// not the mean of error^2 / predicted (a t-like ratio, 24/22 = 1.09 at 24
// degrees of freedom), is what the mean squared error should equal.
double ScatterOverPredicted(const std::vector<Sample>& s, size_t begin, size_t end) {
  double e2 = 0, v = 0;
  for (size_t i = begin; i < end; ++i) e2 += s[i].error_px * s[i].error_px, v += s[i].predicted_variance_px2;
  return e2 / v;
}

TEST(SubpixelSigma, PredictedSigmaMatchesTheScatterUnderWhiteNoise) {
  SyntheticPairSpec spec;
  spec.width = 640;
  spec.height = 240;
  spec.noise_sigma_dn = 0;  // rounded to 8 bits only; the noise is added below
  const SyntheticPair pair = RenderSyntheticPair(spec);
  for (const double noise_dn : {2.0, 4.0}) {
    std::vector<Sample> s = RefineGrid(AddNoise(pair.left, noise_dn, 1), AddNoise(pair.right, noise_dn, 2),
                                       AddNoise(pair.left, noise_dn, 3), AddNoise(pair.right, noise_dn, 4), pair, spec);
    ASSERT_GT(s.size(), 2000u);
    // The mean squared error of N independent samples scatters by
    // sqrt(2/N) relative (2.9% at N = 2320; the errors are Gaussian to first
    // order): 4 of those. Plus the second-order excess the first-order
    // covariance leaves out: J holds the noisy right slope, whose noise is
    // correlated with the interpolated right value's, so the scatter exceeds
    // the prediction by a term that grows as sigma^2: measured on this pair,
    // +4% at 3 DN, +16% at 6 DN, i.e. 0.0045 sigma^2; allowed: 0.005 sigma^2
    // (+2% at 2 DN, the simulator's ~1.7 DN; +8% at 4 DN).
    const auto tolerance = [noise_dn](size_t n) {
      return 4 * std::sqrt(2.0 / double(n)) + 0.005 * noise_dn * noise_dn;
    };
    const double all = ScatterOverPredicted(s, 0, s.size());
    EXPECT_NEAR(all, 1.0, tolerance(s.size())) << "noise " << noise_dn << " DN, " << s.size() << " samples";
    // Per point, not only on average: the better and the worse constrained
    // half of the windows each scatter as predicted. The halves are split by
    // the sigma of another noise draw: split by its own noisy estimate
    // (e'e/(n-3) scatters by 29% at 24 degrees of freedom), the low half
    // would gather the windows whose residual came out low by chance.
    std::sort(s.begin(), s.end(), [](const Sample& a, const Sample& b) { return a.key < b.key; });
    const size_t half = s.size() / 2;
    EXPECT_NEAR(ScatterOverPredicted(s, 0, half), 1.0, tolerance(half)) << "noise " << noise_dn << " DN, low half";
    EXPECT_NEAR(ScatterOverPredicted(s, half, s.size()), 1.0, tolerance(s.size() - half))
        << "noise " << noise_dn << " DN, high half";
    const double low = std::sqrt(s[half / 2].key), high = std::sqrt(s[half + half / 2].key);
    std::printf("noise %.0f DN: %zu samples, scatter/predicted %.3f; sigma quartiles %.4f / %.4f px\n", noise_dn,
                s.size(), all, low, high);
  }
}

}  // namespace
}  // namespace stereorig
