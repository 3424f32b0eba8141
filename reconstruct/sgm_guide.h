// The per-pixel guide of the full-resolution SGM search (SgmMatchGuided,
// census_sgm.h), from the half-resolution map the occupied-band pass
// already computed (matcher.cc, disparity_band.h): each full-resolution
// pixel searches only a window around twice its coarse disparity.
//
// The coarse map has gaps: pixels the coarse pass could not match (steep
// flanks, the shadows beside edges) and the mismatched blobs removed before
// the band was found. Gaps are filled along the row by linear interpolation
// between the nearest matched pixels either side (the nearest one alone
// beyond the row's first or last match), rows without any match from the
// nearest filled rows above and below in the same way, and a map without
// any match gets `fallback_px` everywhere (the band's centre).
#pragma once

#include <opencv2/core.hpp>

namespace stereorig {

// coarse_px: CV_32FC1 over coarse_region (half-resolution image px),
// disparities in half-resolution px, NaN or inf = no match (the band pass
// marks the blobs it removed inf). region: full-resolution
// image px. Returns CV_16SC1 of region.size(): the guide disparity of each
// pixel, full-resolution px (twice the coarse value of the half-resolution
// pixel holding it, rounded).
cv::Mat GuideFromCoarse(const cv::Mat& coarse_px, const cv::Rect& coarse_region, const cv::Rect& region,
                        int fallback_px);

}  // namespace stereorig
