#include "reconstruct/sgm_guide.h"

#include <algorithm>
#include <cmath>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

// Fills the non-finite entries of v[0], v[step], ... v[(n-1)*step] by linear
// interpolation between the nearest finite entries either side, or the
// nearest one alone at the ends. Returns false (v unchanged) if no entry is
// finite.
bool FillLine(float* v, int n, int step) {
  int prev = -1;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i * step])) continue;
    if (prev < 0) {
      for (int k = 0; k < i; ++k) v[k * step] = v[i * step];
    } else {
      const float a = v[prev * step], b = v[i * step];
      for (int k = prev + 1; k < i; ++k) v[k * step] = a + (b - a) * float(k - prev) / float(i - prev);
    }
    prev = i;
  }
  if (prev < 0) return false;
  for (int k = prev + 1; k < n; ++k) v[k * step] = v[prev * step];
  return true;
}

}  // namespace

cv::Mat GuideFromCoarse(const cv::Mat& coarse_px, const cv::Rect& coarse_region, const cv::Rect& region,
                        int fallback_px) {
  STEREORIG_CHECK(coarse_px.type() == CV_32FC1 && coarse_px.size() == coarse_region.size());
  cv::Mat filled = coarse_px.clone();
  bool any = false;
  for (int y = 0; y < filled.rows; ++y) any = FillLine(filled.ptr<float>(y), filled.cols, 1) || any;
  cv::Mat guide(region.size(), CV_16SC1, cv::Scalar(fallback_px));
  if (!any || filled.empty()) return guide;
  // Rows without a match (still all non-finite): from the filled rows above and below.
  for (int x = 0; x < filled.cols; ++x) FillLine(filled.ptr<float>(0) + x, filled.rows, int(filled.step1()));
  for (int y = 0; y < region.height; ++y) {
    const int cy = std::clamp((region.y + y) / 2 - coarse_region.y, 0, filled.rows - 1);
    const float* c = filled.ptr<float>(cy);
    int16_t* g = guide.ptr<int16_t>(y);
    for (int x = 0; x < region.width; ++x) {
      const int cx = std::clamp((region.x + x) / 2 - coarse_region.x, 0, filled.cols - 1);
      g[x] = int16_t(std::lround(2.0 * c[cx]));
    }
  }
  return guide;
}

}  // namespace stereorig
