#include "reconstruct/synthetic_pair.h"

#include <cmath>
#include <random>

namespace stereorig {
namespace {

// Gauss-Legendre nodes/weights on [-1/2, 1/2] (8 points, weights sum to 1).
constexpr double kGlX[8] = {-0.4801449282487681, -0.3983332387068134, -0.2627662049581645, -0.0916826549907388,
                            0.0916826549907388,  0.2627662049581645,  0.3983332387068134,  0.4801449282487681};
constexpr double kGlW[8] = {0.0506142681451881, 0.1111905172266872, 0.1568533229389436, 0.1813418916891810,
                            0.1813418916891810, 0.1568533229389436, 0.1111905172266872, 0.0506142681451881};

struct Wave {
  double ku, kv, phase, amplitude;
};

class Radiance {
 public:
  explicit Radiance(const SyntheticPairSpec& s) : s_(s) {
    std::mt19937_64 rng(s.seed * 7919 + 13);
    std::uniform_real_distribution<double> uni(0, 1);
    // Low-frequency albedo texture: wavelengths 12..60 px, random directions.
    for (int i = 0; i < 6; ++i) {
      const double wavelength = 12 + 48 * uni(rng), dir = 2 * M_PI * uni(rng);
      waves_.push_back({2 * M_PI / wavelength * std::cos(dir), 2 * M_PI / wavelength * std::sin(dir),
                        2 * M_PI * uni(rng), s.texture_contrast / std::sqrt(6.0) * (0.5 + uni(rng))});
    }
    const double a = s.grid_angle_deg * M_PI / 180.0;
    normals_[0][0] = std::cos(a), normals_[0][1] = std::sin(a);   // near-vertical lines
    normals_[1][0] = -std::sin(a), normals_[1][1] = std::cos(a);  // near-horizontal lines
    phases_[0] = 0.37 * s.grid_period_px;
    phases_[1] = 0.71 * s.grid_period_px;
  }

  // Integral over u in [u_lo, u_hi] of the radiance on the row v (left-image
  // coordinates), exact.
  double IntegrateRow(double u_lo, double u_hi, double v) const {
    double total = s_.ambient_dn * (u_hi - u_lo);
    for (const Wave& w : waves_) {
      // integral of A*sin(ku*u + kv*v + p) du
      total -= s_.ambient_dn * w.amplitude / w.ku *
               (std::cos(w.ku * u_hi + w.kv * v + w.phase) - std::cos(w.ku * u_lo + w.kv * v + w.phase));
    }
    if (!s_.laser_on) return total;
    const double p = s_.grid_period_px, sg = s_.grid_sigma_px;
    for (int f = 0; f < 2; ++f) {
      const double nu = normals_[f][0], nv = normals_[f][1];
      const double s_a = nu * u_lo + nv * v - phases_[f], s_b = nu * u_hi + nv * v - phases_[f];
      const double s_min = std::min(s_a, s_b), s_max = std::max(s_a, s_b);
      const int k_lo = int(std::floor((s_min - 6 * sg) / p)), k_hi = int(std::ceil((s_max + 6 * sg) / p));
      double sum = 0;
      for (int k = k_lo; k <= k_hi; ++k) {
        const double c = k * p;
        sum += std::erf((s_b - c) / (M_SQRT2 * sg)) - std::erf((s_a - c) / (M_SQRT2 * sg));
      }
      // d s = nu du, so the integral over u is (1/nu) times the one over s.
      total += s_.grid_amplitude_dn * sg * std::sqrt(M_PI / 2) / nu * sum;
    }
    return total;
  }

 private:
  const SyntheticPairSpec& s_;
  std::vector<Wave> waves_;
  double normals_[2][2];
  double phases_[2];
};

}  // namespace

SyntheticPair RenderSyntheticPair(const SyntheticPairSpec& s) {
  const Radiance radiance(s);
  SyntheticPair out;
  out.left_clean = cv::Mat(s.height, s.width, CV_64FC1);
  cv::Mat right_clean(s.height, s.width, CV_64FC1);
  out.true_disparity_px = cv::Mat(s.height, s.width, CV_64FC1);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      double l = 0, r = 0;
      for (int q = 0; q < 8; ++q) {
        const double v = y + kGlX[q];
        l += kGlW[q] * radiance.IntegrateRow(x - 0.5, x + 0.5, v);
        // Right pixel X sees left u with X = u - d(u, v) = u (1 - du) - d0 - dv v,
        // on the left's row v = its own less the right view's row offset.
        const double vr = v - s.right_row_offset_px;
        const double ua = (x - 0.5 + s.d0_px + s.dv * vr) / (1 - s.du);
        const double ub = (x + 0.5 + s.d0_px + s.dv * vr) / (1 - s.du);
        r += kGlW[q] * radiance.IntegrateRow(ua, ub, vr) / (ub - ua);
      }
      out.left_clean.at<double>(y, x) = l;
      right_clean.at<double>(y, x) = r;
      out.true_disparity_px.at<double>(y, x) = s.d0_px + s.du * x + s.dv * y;
    }
  }
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> noise(0, s.noise_sigma_dn);
  auto quantise = [&](const cv::Mat& clean) {
    cv::Mat img(clean.size(), CV_8UC1);
    for (int y = 0; y < clean.rows; ++y)
      for (int x = 0; x < clean.cols; ++x)
        img.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(std::lround(clean.at<double>(y, x) + noise(rng)));
    return img;
  };
  out.left = quantise(out.left_clean);
  out.right = quantise(right_clean);
  return out;
}

void EndPlaneAtColumn(int edge_x, uint8_t background_dn, SyntheticPair* pair) {
  for (int y = 0; y < pair->left.rows; ++y) {
    for (int x = edge_x; x < pair->left.cols; ++x) pair->left.at<uint8_t>(y, x) = background_dn;
    const double edge_right = edge_x - pair->true_disparity_px.at<double>(y, edge_x);
    for (int x = int(std::ceil(edge_right)); x < pair->right.cols; ++x) pair->right.at<uint8_t>(y, x) = background_dn;
  }
}

}  // namespace stereorig
