// Rectified stereo pairs with a known sub-pixel disparity field, rendered
// analytically, for testing matchers against ground truth.
//
// The scene is a plane seen by a rectified pair: its disparity is affine in
// the left image, d(u, v) = d0 + du * u + dv * v (px). The plane carries
//   - a projected laser grid: two families of Gaussian lines (sigma, period)
//     turned by `grid_angle_deg` against the rows, added to
//   - a weakly textured Lambertian albedo lit by ambient light: a sum of a few
//     low-frequency sinusoids of small amplitude.
// Each pixel is the exact mean of that radiance over the pixel's area: the
// integral along the row is analytic (erf for the lines, cosines for the
// texture; the right image's row maps affinely onto the left's), the one
// across the row uses 8-point Gauss-Legendre quadrature. Then Gaussian sensor
// noise is added and the result is rounded to 8 bits.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace stereorig {

struct SyntheticPairSpec {
  int width = 320, height = 240;     // px
  double d0_px = 40.0;               // disparity at pixel (0, 0)
  double du = 0.04, dv = 0.015;      // disparity gradient along x and y, px/px
  double grid_period_px = 8.0;       // line spacing
  double grid_sigma_px = 1.1;        // Gaussian line half width (1 sigma)
  double grid_angle_deg = 2.6;       // angle of the grid against the rows
  double grid_amplitude_dn = 150.0;  // peak of one line, grey levels
  double ambient_dn = 40.0;          // mean ambient radiance, grey levels
  double texture_contrast = 0.15;    // relative amplitude of the albedo texture
  bool laser_on = true;              // false: passive (ambient only)
  double noise_sigma_dn = 2.0;       // sensor noise, grey levels (1 sigma)
  // The right view's rows moved down by this (a rectification off by a
  // fraction of a row): right row y + offset sees what left row y sees.
  double right_row_offset_px = 0.0;
  uint64_t seed = 1;
};

struct SyntheticPair {
  cv::Mat left, right;        // CV_8UC1
  cv::Mat left_clean;         // CV_64FC1, before noise and rounding
  cv::Mat true_disparity_px;  // CV_64FC1: d at each left pixel centre
};

SyntheticPair RenderSyntheticPair(const SyntheticPairSpec& spec);

// The plane ends at column edge_x of the left image against a flat
// background (an object's silhouette): the left pixels from edge_x on, and
// the right pixels from that column's match on, are set to background_dn.
// true_disparity_px is left as it is (the plane's).
void EndPlaneAtColumn(int edge_x, uint8_t background_dn, SyntheticPair* pair);

}  // namespace stereorig
