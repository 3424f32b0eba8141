#include "apps/rectified_pairs.h"

#include <filesystem>

#include "apps/cli_util.h"
#include "calib/core/png_writer.h"

namespace stereorig {

namespace {

std::string EncodeGreyPng(const cv::Mat& image) {
  return EncodePng(PngImage{.width_px = uint32_t(image.cols),
                            .height_px = uint32_t(image.rows),
                            .channels = 1,
                            .bit_depth = 8,
                            .pixels = image.data,
                            .row_stride_bytes = image.step},
                   1);  // fastest, as the simulator writes its captures
}

}  // namespace

std::vector<RectifiedPairPaths> RectifiedPairPathsIn(const std::string& dir, int num_modules) {
  std::vector<RectifiedPairPaths> paths;
  for (int m = 0; m < num_modules; ++m) {
    const std::string stem = (std::filesystem::path(dir) / ("module" + std::to_string(m))).string();
    paths.push_back({stem + "_left.png", stem + "_right.png", stem + "_disparity.pfm"});
  }
  return paths;
}

void AddRectifiedPairs(const Runtime& runtime, const std::vector<cv::Mat>& images,
                       const std::vector<RectifiedPairPaths>& paths, AtomicOutputSet* written) {
  for (const ModulePlan& plan : runtime.plans()) {
    const auto [left, right] = runtime.Rectify(plan, images);
    written->Add(paths[size_t(plan.module)].left, EncodeGreyPng(left));
    written->Add(paths[size_t(plan.module)].right, EncodeGreyPng(right));
  }
}

std::string RectifiedPairLine(const ModulePlan& plan, const RectifiedPairPaths& paths) {
  const cv::Rect& roi = plan.roi;
  return "module " + std::to_string(plan.module) + ": rectified pair " + paths.left + ", " + paths.right +
         "; the volume's search: stereorig match --left " + ShellQuoted(paths.left) + " --right " +
         ShellQuoted(paths.right) + " --min-disparity " + std::to_string(plan.min_disparity_px) +
         " --num-disparities " + std::to_string(plan.num_disparities) + " --roi " + std::to_string(roi.x) + " " +
         std::to_string(roi.y) + " " + std::to_string(roi.width) + " " + std::to_string(roi.height) + " --out " +
         ShellQuoted(paths.disparity);
}

}  // namespace stereorig
