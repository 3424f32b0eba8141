// Removal of small blobs from a fixed-point disparity map: the result of
// OpenCV's cv::filterSpeckles on CV_16SC1, from a two-pass union-find
// labelling instead of its flood fill (about half the instructions: the
// flood fill visits each pixel through a stack and tests its four
// neighbours twice, from either side).
//
// A blob is a 4-connected set of valid pixels (value != invalid) in which
// neighbours differ by at most max_diff; blobs of at most max_blob_px pixels
// become `invalid`. Blobs are a property of the map alone, so the labelling
// order does not change which pixels go (speckle_filter_test.cc checks it
// against cv::filterSpeckles bit for bit).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace stereorig {

// disparity_16: CV_16SC1, may be a view (only its own pixels are read and
// written). max_blob_px <= 0 removes nothing; max_diff >= 0.
// step_left_16, step_up_16: empty (as cv::filterSpeckles), or CV_16SC1 of
// disparity_16's size: the step each pixel's value is expected to make from
// its left and upper neighbour's (a sloping surface's), which the test
// then allows for: neighbours a, b (b right of or below a) are one blob if
// |b - a - step at b| <= max_diff.
void FilterSpeckles16(cv::Mat disparity_16, int16_t invalid, int max_blob_px, int max_diff,
                      const cv::Mat& step_left_16 = cv::Mat(), const cv::Mat& step_up_16 = cv::Mat());

// The same on a float map (CV_32FC1, may be a view, written in place), as
// the matcher's speckle filter runs it: on a copy in 1/16 px (each finite
// value clamped to +-2000 px and rounded half away from zero, as
// std::lround), blobs whose neighbours differ by at most max_diff_px
// (rounded to sixteenths likewise); removed and non-finite pixels become +inf.
void RemoveSpeckleBlobs(cv::Mat disparity_px, int max_blob_px, double max_diff_px);

// The same on a surface's disparity map whose local slopes are known
// (slope_x = dd/dx, slope_y = dd/dy, px/px; CV_32FC1 views of
// disparity_px's size; 0 where unknown). Where both neighbours' slopes
// step more than max_diff_px per px, the same way, the plain test can never
// join them, and a surface that steep is cut into one-pixel strips, every
// one removed: 1 - dd/dx, the width ratio of a surface patch in the right
// view to the left, is unbounded above (disparity_slopes.h,
// IsSurfaceSlope), and a plate 60 degrees to a ring module's axis reads
// dd/dx = -1.6 px/px. There, and only there, neighbours are one blob if
// their difference is within max_diff_px of the step their mean slope
// predicts; elsewhere this is RemoveSpeckleBlobs. (Taking every difference
// from its predicted step also joined, at twice the default laser speckle,
// patches a grid period off to their neighbours through the rising slopes
// of limbs, +0.05 mm std on a tuber; taking it where only the mean slope
// was beyond the reach, +0.0023 mm on a ball bar; docs/reconstruct-log.md,
// "The oblique plate (session 22)".)
void RemoveSpeckleBlobsAlongSlopes(cv::Mat disparity_px, const cv::Mat& slope_x, const cv::Mat& slope_y,
                                   int max_blob_px, double max_diff_px);

}  // namespace stereorig
