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
void FilterSpeckles16(cv::Mat disparity_16, int16_t invalid, int max_blob_px, int max_diff);

// The same on a float map (CV_32FC1, may be a view, written in place), as
// the matcher's speckle filter runs it: on a copy in 1/16 px (each finite
// value clamped to +-2000 px and rounded half away from zero, as
// std::lround), blobs whose neighbours differ by at most max_diff_px
// (rounded to sixteenths likewise); removed and non-finite pixels become +inf.
void RemoveSpeckleBlobs(cv::Mat disparity_px, int max_blob_px, double max_diff_px);

}  // namespace stereorig
