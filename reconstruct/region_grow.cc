#include "reconstruct/region_grow.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/local_plane.h"
#include "reconstruct/shifted_window.h"
#include "reconstruct/validity_bits.h"

namespace stereorig {

void GrowOptions::Check() const {
  if (!(max_deviation_px > 0 && max_deviation_px <= 4)) throw InputError("grow_max_deviation_px", "must be in (0, 4]");
  if (max_tries < 1 || max_tries > 8) throw InputError("grow_max_tries", "must be in [1, 8]");
  if (plane_radius_px < 1 || plane_radius_px > 10) throw InputError("grow_plane_radius_px", "must be in [1, 10]");
  oblique.Check();
  if (!(shifted_min_foreshortening > 0 && shifted_min_foreshortening <= 1))
    throw InputError("grow_shifted_min_foreshortening", "must be in (0, 1]");
  if (!(shifted_min_zncc >= -1 && shifted_min_zncc < 1))
    throw InputError("grow_shifted_min_zncc", "must be in [-1, 1)");
  if (!(shifted_enclosed_min_zncc >= -1 && shifted_enclosed_min_zncc < 1))
    throw InputError("grow_shifted_enclosed_min_zncc", "must be in [-1, 1)");
  if (!(noise_zncc_factor >= 0 && noise_zncc_factor <= 20))
    throw InputError("grow_noise_zncc_factor", "must be in [0, 20] (0 = off)");
  if (!(noise_min_zncc >= -1 && noise_min_zncc < 1)) throw InputError("grow_noise_min_zncc", "must be in [-1, 1)");
}

double GrowMinZncc(const cv::Mat& disparity_px, const cv::Mat& confidence, const cv::Rect& roi, const GrowOptions& o,
                   double min_zncc) {
  if (!(o.noise_zncc_factor > 0)) return min_zncc;
  STEREORIG_CHECK(disparity_px.type() == CV_32FC1 && confidence.type() == CV_32FC1 &&
                  disparity_px.size() == confidence.size());
  std::vector<float> decorrelation;
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const float* d = disparity_px.ptr<float>(y);
    const float* c = confidence.ptr<float>(y);
    for (int x = roi.x; x < roi.x + roi.width; ++x)
      if (std::isfinite(d[x])) decorrelation.push_back(1.0f - c[x]);
  }
  if (decorrelation.empty()) return min_zncc;
  const auto mid = decorrelation.begin() + std::ptrdiff_t(decorrelation.size() / 2);
  std::nth_element(decorrelation.begin(), mid, decorrelation.end());
  const double floor = 1.0 - o.noise_zncc_factor * double(*mid);
  return std::min(min_zncc, std::max(o.noise_min_zncc, floor));
}

namespace {

// Whether pixel q, grown from its neighbour q + from along the row, lies in
// a hole of the matched surface rather than at its edge: some pixel on the
// far side, q - k from for k = 1 .. the window's half width, holds a
// disparity. At a silhouette or the lit region's end that side is
// background: nothing. Never for a pixel grown from the row above or below:
// its shifted window moves by one row and still spans the whole row
// segment, so at a silhouette along the row a pixel found on the far row
// proves nothing (letting those in put the plate's module 1 std at speckle 0
// from 0.062 to 0.122 mm).
bool Enclosed(const cv::Mat& disparity, const cv::Rect& roi, cv::Point q, cv::Point from, const SubpixelOptions& w) {
  if (from.x == 0) return false;
  for (int k = 1; k <= w.half_width_px; ++k) {
    const cv::Point beyond = q - from * k;
    if (!roi.contains(beyond)) return false;
    if (std::isfinite(disparity.at<float>(beyond))) return true;
  }
  return false;
}

}  // namespace

GrowMemory::GrowMemory(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const GrowOptions& options)
    : roi_(roi),
      oblique_(left, right, roi.y - 8, roi.y + roi.height + 8, options.oblique),
      latest_failed_(size_t(roi.area()), 0) {}

int GrowDisparity(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const GrowOptions& o,
                  const RefineAcceptance& accept, DisparityState* state, GrowMemory* memory) {
  if (!o.enabled) return 0;
  std::optional<GrowMemory> own_memory;
  if (!memory) memory = &own_memory.emplace(left, right, roi, o);
  STEREORIG_CHECK(memory->roi_ == roi);
  cv::Mat& disparity = state->disparity_px;
  // Per pixel of roi, row-major.
  auto index = [&](cv::Point q) { return size_t(q.y - roi.y) * size_t(roi.width) + size_t(q.x - roi.x); };
  std::vector<uint8_t> tried(size_t(roi.area()), 0);
  RefineAcceptance shifted_accept = accept;
  shifted_accept.min_zncc = std::max(accept.min_zncc, o.shifted_min_zncc);
  RefineAcceptance enclosed_accept = accept;
  enclosed_accept.min_zncc = std::max(accept.min_zncc, o.shifted_enclosed_min_zncc);
  // Breadth first: a flat queue, popped from `head`, seeded with the valid
  // pixels in raster order. Only those with an empty 4-neighbour in roi:
  // the others have nothing to try (a valid pixel stays valid), so leaving
  // them out changes nothing but the time (most of the map is interior).
  ValidityBits valid(disparity, roi);  // kept in step with `disparity` below
  std::vector<cv::Point> queue = valid.EdgePixels();
  int added = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const cv::Point p = queue[head];
    const float d = disparity.at<float>(p);
    const float gx = state->slope_x.at<float>(p), gy = state->slope_y.at<float>(p);
    const cv::Point next[4] = {{p.x - 1, p.y}, {p.x + 1, p.y}, {p.x, p.y - 1}, {p.x, p.y + 1}};
    for (const cv::Point& q : next) {
      // A pixel is tried again from later neighbours (up to max_tries): by
      // then more of its neighbourhood is known, so the prediction is better.
      if (!roi.contains(q) || std::isfinite(disparity.at<float>(q))) continue;
      uint8_t& tries = tried[index(q)];
      if (tries >= o.max_tries) continue;
      ++tries;
      // Predicted from the plane through the valid neighbours (noise ~0.25 px
      // per pixel averages out), else from p and its slopes.
      LocalPlane plane{d + gx * (q.x - p.x) + gy * (q.y - p.y), gx, gy};
      FitLocalPlane(disparity, valid, roi, q, o.plane_radius_px, &plane);
      const double predicted = plane.disparity_px, qgx = plane.slope_x, qgy = plane.slope_y;
      const cv::Point from = p - q;
      const bool enclosed = o.shifted_windows && Enclosed(disparity, roi, q, from, accept.subpixel);
      // Tried exactly so before and failed: it fails again, as before.
      int32_t& latest = memory->latest_failed_[index(q)];
      const GrowMemory::FailedTry* repeat = nullptr;
      for (int32_t i = latest; i != 0 && !repeat; i = memory->failed_[size_t(i - 1)].previous) {
        const GrowMemory::FailedTry& f = memory->failed_[size_t(i - 1)];
        if (f.start_px == predicted && f.slope_x == qgx && f.slope_y == qgy &&
            (!o.shifted_windows || (f.from_dx == from.x && f.from_dy == from.y && f.enclosed == enclosed)))
          repeat = &f;
      }
      if (repeat) {
        state->status.at<uint8_t>(q) = repeat->status;
        continue;
      }
      SubpixelResult r;
      PixelStatus why = RefineAndAccept(left, right, q.x, q.y, predicted, qgx, qgy, accept, &r);
      if (why == PixelStatus::kPoint && std::abs(r.disparity_px - predicted) > o.max_deviation_px)
        why = PixelStatus::kOffPlane;
      if (why != PixelStatus::kPoint && o.shifted_windows && 1 - qgx > o.shifted_min_foreshortening &&
          1 - qgx < 1 / o.shifted_min_foreshortening) {
        SubpixelResult shifted;
        if (RefineShiftedWindow(left, right, q.x, q.y, from, predicted, qgx, qgy,
                                enclosed ? enclosed_accept : shifted_accept, o.max_deviation_px,
                                &shifted) == PixelStatus::kPoint) {
          r = shifted;
          why = PixelStatus::kPoint;
        }
      }
      if (why != PixelStatus::kPoint) {
        SubpixelResult oblique_result;
        PixelStatus oblique_why;
        if (memory->oblique_.Refine(q.x, q.y, predicted, qgx, qgy, accept, &oblique_result, &oblique_why) &&
            oblique_why == PixelStatus::kPoint &&
            std::abs(oblique_result.disparity_px - predicted) <= o.max_deviation_px) {
          r = oblique_result;
          why = PixelStatus::kPoint;
        }
      }
      if (why != PixelStatus::kPoint) {
        state->status.at<uint8_t>(q) = uint8_t(why);  // the reason growing could not reach it
        memory->failed_.push_back(
            {predicted, qgx, qgy, latest, int8_t(from.x), int8_t(from.y), uint8_t(why), enclosed});
        latest = int32_t(memory->failed_.size());
        continue;
      }
      disparity.at<float>(q) = float(r.disparity_px);
      valid.Set(q.x, q.y, std::isfinite(disparity.at<float>(q)));
      state->confidence.at<float>(q) = float(std::clamp(r.zncc, 0.0, 1.0));
      state->status.at<uint8_t>(q) = uint8_t(PixelStatus::kPoint);
      state->slope_x.at<float>(q) = float(qgx);
      state->slope_y.at<float>(q) = float(qgy);
      queue.push_back(q);
      ++added;
    }
  }
  return added;
}

}  // namespace stereorig
