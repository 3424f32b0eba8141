#include "reconstruct/lit_mask.h"

#include <cstdint>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

// Built without -march=native (reconstruct/CMakeLists.txt): no FMA may fuse
// mean2 - mean * mean, whose float product boxFilter's users round first.
cv::Mat LitMask(const cv::Mat& grey, double contrast_dn) {
  STEREORIG_CHECK(grey.type() == CV_8UC1);
  constexpr int kHalf = 4;  // the 9x9 window
  const int w = grey.cols, h = grey.rows;
  cv::Mat lit(grey.size(), CV_8UC1, cv::Scalar(0));
  if (w == 0 || h == 0) return lit;
  // Reflected column and row of every window position (index + kHalf).
  std::vector<int> col(w + 2 * kHalf), row(h + 2 * kHalf);
  for (int i = 0; i < w + 2 * kHalf; ++i) col[i] = cv::borderInterpolate(i - kHalf, w, cv::BORDER_REFLECT_101);
  for (int i = 0; i < h + 2 * kHalf; ++i) row[i] = cv::borderInterpolate(i - kHalf, h, cv::BORDER_REFLECT_101);
  // Column sums of g and g^2 over the window's 9 rows, at every padded column.
  std::vector<int32_t> sum(w + 2 * kHalf, 0), sum2(w + 2 * kHalf, 0);
  auto add_row = [&](int r, int sign) {
    const uint8_t* g = grey.ptr<uint8_t>(r);
    for (int i = 0; i < w + 2 * kHalf; ++i) {
      const int32_t v = g[col[i]];
      sum[i] += sign * v;
      sum2[i] += sign * v * v;
    }
  };
  for (int k = 0; k < 2 * kHalf + 1; ++k) add_row(row[k], 1);
  const float threshold = float(contrast_dn * contrast_dn);
  const double scale = 1.0 / ((2 * kHalf + 1) * (2 * kHalf + 1));  // boxFilter's, applied to its double sums
  for (int y = 0; y < h; ++y) {
    if (y > 0) add_row(row[y + 2 * kHalf], 1), add_row(row[y - 1], -1);
    int32_t s = 0, s2 = 0;
    for (int i = 0; i < 2 * kHalf; ++i) s += sum[i], s2 += sum2[i];
    uint8_t* out = lit.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      s += sum[x + 2 * kHalf], s2 += sum2[x + 2 * kHalf];
      const float mean = float(s * scale), mean2 = float(s2 * scale);
      const float square = mean * mean;
      out[x] = mean2 - square > threshold ? 255 : 0;
      s -= sum[x], s2 -= sum2[x];
    }
  }
  return lit;
}

}  // namespace stereorig
