#include "reconstruct/line_index.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

void LineIndexOptions::Check() const {
  if (max_shift_px < 2 || max_shift_px > 64) throw InputError("line_index_max_shift_px", "must be in [2, 64]");
  if (min_component_px < 1) throw InputError("line_index_min_component_px", "must be >= 1");
  if (samples < 4 || samples > 10000) throw InputError("line_index_samples", "must be in [4, 10000]");
  if (window_half_height_px < 0 || window_half_height_px > 30)
    throw InputError("line_index_window_half_height_px", "must be in [0, 30]");
  if (!(max_row_offset_px > 0 && max_row_offset_px < 1))
    throw InputError("line_index_max_row_offset_px", "must be in (0, 1)");
  if (!(min_row_offset_step_px > 0 && min_row_offset_step_px < 1))
    throw InputError("line_index_min_row_offset_step_px", "must be in (0, 1)");
}

cv::Mat LabelDisparityComponents(const cv::Mat& disparity_px, const cv::Rect& roi, double max_step_px,
                                 std::vector<std::vector<int>>* components) {
  const int cols = disparity_px.cols;
  cv::Mat labels(disparity_px.size(), CV_32SC1, cv::Scalar(-1));
  components->clear();
  std::vector<int> stack;
  for (int y = roi.y; y < roi.y + roi.height; ++y)
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      if (labels.at<int>(y, x) >= 0 || !std::isfinite(disparity_px.at<float>(y, x))) continue;
      const int label = int(components->size());
      components->emplace_back();
      std::vector<int>& pixels = components->back();
      labels.at<int>(y, x) = label;
      stack.assign(1, y * cols + x);
      while (!stack.empty()) {
        const int i = stack.back();
        stack.pop_back();
        pixels.push_back(i);
        const int py = i / cols, px = i % cols;
        const float d = disparity_px.at<float>(py, px);
        const int nx[4] = {px - 1, px + 1, px, px}, ny[4] = {py, py, py - 1, py + 1};
        for (int k = 0; k < 4; ++k) {
          if (!roi.contains(cv::Point(nx[k], ny[k]))) continue;
          int& l = labels.at<int>(ny[k], nx[k]);
          const float dn = disparity_px.at<float>(ny[k], nx[k]);
          if (l >= 0 || !std::isfinite(dn) || std::abs(dn - d) > max_step_px) continue;
          l = label;
          stack.push_back(ny[k] * cols + nx[k]);
        }
      }
    }
  return labels;
}

namespace {

struct Vernier {
  double mean_row_offset_px = 0;  // over the sample's successful fits
  double standard_error_px = 1e9;
  double mean_shift_px = 0;  // mean of (fitted - starting disparity) + the shift tried
  int fits = 0;
};

}  // namespace

int CorrectLineIndex(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const LineIndexOptions& o,
                     const RefineAcceptance& accept, DisparityState* state) {
  if (!o.enabled) return 0;
  std::vector<std::vector<int>> components;
  LabelDisparityComponents(state->disparity_px, roi, 1.0, &components);
  const int cols = left.cols;
  SubpixelOptions tall = accept.subpixel;
  tall.half_height_px = o.window_half_height_px;
  auto at = [&](const cv::Mat& m, int i) { return m.at<float>(i / cols, i % cols); };
  // The row offset of the tall-window fit over `sample`, each started from
  // its disparity + shift.
  auto vernier = [&](const std::vector<int>& sample, double shift) {
    double sum = 0, sum2 = 0, sum_shift = 0;
    int n = 0;
    for (int i : sample) {
      const RowOffsetResult r =
          RefineDisparityAndRowOffset(left, right, i % cols, i / cols, at(state->disparity_px, i) + shift,
                                      at(state->slope_x, i), at(state->slope_y, i), tall);
      if (!r.ok) continue;
      sum += r.row_offset_px, sum2 += r.row_offset_px * r.row_offset_px;
      sum_shift += r.disparity_px - at(state->disparity_px, i);
      ++n;
    }
    Vernier v;
    v.fits = n;
    if (n >= 4) {
      v.mean_row_offset_px = sum / n;
      v.mean_shift_px = sum_shift / n;
      v.standard_error_px = std::sqrt(std::max(0.0, sum2 / n - v.mean_row_offset_px * v.mean_row_offset_px) / (n - 1));
    }
    return v;
  };
  // Mean ZNCC of the matcher's own refinement from disparity + shift.
  auto mean_zncc = [&](const std::vector<int>& sample, double shift) {
    double sum = 0;
    for (int i : sample) {
      const SubpixelResult r = RefineDisparity(left, right, i % cols, i / cols, at(state->disparity_px, i) + shift,
                                               at(state->slope_x, i), at(state->slope_y, i), accept.subpixel);
      sum += r.ok ? r.zncc : 0.0;
    }
    return sum / double(sample.size());
  };
  int moved = 0;
  for (const std::vector<int>& pixels : components) {
    if (int(pixels.size()) < o.min_component_px) continue;
    // Up to two moves: a component can be two periods off.
    for (int round = 0; round < 2; ++round) {
      std::vector<int> sample;
      {
        std::vector<int> valid;
        for (int i : pixels)
          if (std::isfinite(at(state->disparity_px, i))) valid.push_back(i);
        const double stride = std::max(1.0, double(valid.size()) / o.samples);
        for (double k = 0.5 * stride; k < double(valid.size()); k += stride) sample.push_back(valid[size_t(k)]);
      }
      if (int(sample.size()) < 4) break;
      const Vernier here = vernier(sample, 0.0);
      const double here_abs = std::abs(here.mean_row_offset_px);
      if (getenv("LI_DEBUG"))
        std::fprintf(stderr, "component %zu px: dy %+.3f se %.3f (%d fits)\n", pixels.size(), here.mean_row_offset_px,
                     here.standard_error_px, here.fits);
      if (here.fits < 4 || here_abs <= std::max(o.max_row_offset_px, 3 * here.standard_error_px)) break;
      // The other alignments: on each side, the shift whose refinement
      // correlates best. Their row offsets step by about the same amount
      // per period (the vernier): fit dy(k) = a + b k over k = -1, 0, +1 and
      // move to the alignment nearest its zero crossing.
      Vernier side[2];
      double side_shift[2] = {0, 0};
      for (int j = 0; j < 2; ++j) {
        const int sign = j == 0 ? -1 : 1;
        double best_z = -2;
        for (int s = 2; s <= o.max_shift_px; ++s) {
          const double z = mean_zncc(sample, sign * s);
          if (z > best_z) best_z = z, side_shift[j] = sign * s;
        }
        side[j] = vernier(sample, side_shift[j]);
        if (getenv("LI_DEBUG"))
          std::fprintf(stderr, "   shift %+.0f: zncc %.3f dy %+.3f se %.3f (%d fits) -> %+.2f\n", side_shift[j], best_z,
                       side[j].mean_row_offset_px, side[j].standard_error_px, side[j].fits, side[j].mean_shift_px);
      }
      double sw = 0, sk = 0, skk = 0, sd = 0, skd = 0;
      const Vernier* points[3] = {&side[0], &here, &side[1]};
      for (int k = -1; k <= 1; ++k) {
        const Vernier& v = *points[k + 1];
        if (v.fits < 4) continue;
        const double w = 1.0 / (v.standard_error_px * v.standard_error_px + 1e-4);
        sw += w, sk += w * k, skk += w * k * k, sd += w * v.mean_row_offset_px, skd += w * k * v.mean_row_offset_px;
      }
      const double det = sw * skk - sk * sk;
      if (!(det > 0)) break;
      const double a = (skk * sd - sk * skd) / det, b = (sw * skd - sk * sd) / det;
      if (std::abs(b) < o.min_row_offset_step_px) break;  // no vernier to read
      const int k = int(std::lround(std::clamp(-a / b, -1.0, 1.0)));
      if (k == 0 || points[k + 1]->fits < 4) break;
      const Vernier& best = *points[k + 1];
      ++moved;
      // Re-refine every pixel: the period varies over a curved surface, so
      // from starts 2 px either side of the sample's mean fitted shift (the
      // other alignments are a period away), keeping the best correlation.
      for (int i : pixels) {
        const int y = i / cols, x = i % cols;
        float& d = state->disparity_px.at<float>(y, x);
        if (!std::isfinite(d)) continue;
        SubpixelResult r;
        for (int k = -2; k <= 2; ++k) {
          const SubpixelResult rk =
              RefineDisparity(left, right, x, y, d + best.mean_shift_px + k, state->slope_x.at<float>(y, x),
                              state->slope_y.at<float>(y, x), accept.subpixel);
          if (rk.ok && (!r.ok || rk.zncc > r.zncc)) r = rk;
        }
        const PixelStatus why =
            Accept(left, right, x, y, state->slope_x.at<float>(y, x), state->slope_y.at<float>(y, x), r, accept);
        state->status.at<uint8_t>(y, x) = uint8_t(why);
        if (why == PixelStatus::kPoint) {
          d = float(r.disparity_px);
          state->confidence.at<float>(y, x) = float(std::clamp(r.zncc, 0.0, 1.0));
        } else {
          d = std::numeric_limits<float>::infinity();
          state->confidence.at<float>(y, x) = 0;
        }
      }
    }
  }
  return moved;
}

}  // namespace stereorig
