// Test helper: a DisparityState whose every pixel is a point (status kPoint,
// confidence 0.9, slopes 0) at the given disparities (+inf: none, status
// still kPoint; set it where a test needs another).
#pragma once

#include <opencv2/core.hpp>

#include "reconstruct/disparity_state.h"

namespace stereorig::testing {

inline DisparityState StateOf(const cv::Mat& disparity) {
  return DisparityState{disparity.clone(), cv::Mat(disparity.size(), CV_32FC1, cv::Scalar(0.9)),
                        cv::Mat(disparity.size(), CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kPoint))),
                        cv::Mat(disparity.size(), CV_32FC1, cv::Scalar(0)),
                        cv::Mat(disparity.size(), CV_32FC1, cv::Scalar(0))};
}

}  // namespace stereorig::testing
