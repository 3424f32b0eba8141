#include "reconstruct/fill_diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "calib/core/input_error.h"
#include "calib/core/png_writer.h"
#include "reconstruct/matcher.h"
#include "reconstruct/oblique_refine.h"

namespace stereorig {

double TruthSlopePx(float before_px, float centre_px, float after_px) {
  const bool has_before = std::isfinite(before_px), has_after = std::isfinite(after_px);
  if (has_before && has_after) return 0.5 * (double(after_px) - before_px);
  if (!std::isfinite(centre_px)) return 0.0;
  if (has_after) return double(after_px) - centre_px;
  if (has_before) return double(centre_px) - before_px;
  return 0.0;
}

SilhouetteErrorProfile ProfileSilhouetteError(const cv::Mat& disparity_px, const cv::Mat& truth_disparity,
                                              const cv::Mat& status, const cv::Mat& left_valid) {
  STEREORIG_CHECK(disparity_px.type() == CV_32FC1 && truth_disparity.type() == CV_32FC1 && status.type() == CV_8UC1);
  STEREORIG_CHECK(disparity_px.size() == status.size() && truth_disparity.size() == status.size());
  STEREORIG_CHECK(left_valid.empty() || (left_valid.type() == CV_8UC1 && left_valid.size() == status.size()));
  constexpr int kMax = SilhouetteErrorProfile::kMaxDistancePx;
  SilhouetteErrorProfile p;
  double interior_sum = 0;
  for (int y = 0; y < status.rows; ++y) {
    const float* truth = truth_disparity.ptr<float>(y);
    const float* disparity = disparity_px.ptr<float>(y);
    const uint8_t* st = status.ptr<uint8_t>(y);
    const uint8_t* valid = left_valid.empty() ? nullptr : left_valid.ptr<uint8_t>(y);
    // Distance to the first pixel without truth at x + k (step +1) or x - k
    // (step -1), k <= kMax; 0 if there is none that near, or the first is
    // past the image's border or the left view's data (not a silhouette).
    auto silhouette_distance = [&](int x, int step) {
      for (int k = 1; k <= kMax; ++k) {
        const int xs = x + step * k;
        if (xs < 0 || xs >= truth_disparity.cols) return 0;
        if (!std::isfinite(truth[xs])) return valid && !valid[xs] ? 0 : k;
      }
      return 0;
    };
    for (int x = 0; x < status.cols; ++x) {
      if (st[x] != uint8_t(PixelStatus::kPoint) || !std::isfinite(disparity[x]) || !std::isfinite(truth[x])) continue;
      const double e = double(disparity[x]) - truth[x];
      const bool off = std::abs(e) > 1;
      const int right = silhouette_distance(x, +1), left = silhouette_distance(x, -1);
      if (right > 0) ++p.right_count[right], p.right_off_1px[right] += off, p.right_mean_px[right] += e;
      if (left > 0) ++p.left_count[left], p.left_off_1px[left] += off, p.left_mean_px[left] += e;
      if (right == 0 && left == 0) ++p.interior_count, p.interior_off_1px += off, interior_sum += e;
    }
  }
  for (int k = 1; k <= kMax; ++k) {
    if (p.right_count[k] > 0) p.right_mean_px[k] /= p.right_count[k];
    if (p.left_count[k] > 0) p.left_mean_px[k] /= p.left_count[k];
  }
  if (p.interior_count > 0) p.interior_mean_px = interior_sum / p.interior_count;
  return p;
}

std::string SilhouetteErrorProfile::Summary() const {
  std::string s = "mean d - truth by distance to the silhouette along the row, px (k: points (> 1 px off): mean):";
  char buf[64];
  for (const auto& [side, count, off, mean] : {std::tuple{"right", &right_count, &right_off_1px, &right_mean_px},
                                               std::tuple{"left", &left_count, &left_off_1px, &left_mean_px}}) {
    s += std::string(" ") + side;
    bool any = false;
    for (int k = 1; k <= kMaxDistancePx; ++k) {
      if ((*count)[k] == 0) continue;
      std::snprintf(buf, sizeof buf, " %d: %d (%d): %+.2f", k, (*count)[k], (*off)[k], (*mean)[k]);
      s += buf, any = true;
    }
    s += any ? ";" : " none;";
  }
  std::snprintf(buf, sizeof buf, " farther: %d (%d): %+.3f\n", interior_count, interior_off_1px, interior_mean_px);
  return s + buf;
}

cv::Mat TruthDisparity(const ModulePlan& plan, const cv::Mat& left_x, const cv::Mat& left_y,
                       const cv::Mat& left_depth_mm) {
  const RectifiedGeometry& g = plan.geometry;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat out(g.size, CV_32FC1, cv::Scalar(nan));
  const Eigen::Matrix3d left_from_rect = g.rect_from_left.transpose();
  for (int v = 0; v < out.rows; ++v)
    for (int u = 0; u < out.cols; ++u) {
      const double ox = left_x.at<float>(v, u), oy = left_y.at<float>(v, u);
      const int x0 = int(std::floor(ox)), y0 = int(std::floor(oy));
      if (x0 < 0 || y0 < 0 || x0 + 1 >= left_depth_mm.cols || y0 + 1 >= left_depth_mm.rows) continue;
      const float z00 = left_depth_mm.at<float>(y0, x0), z01 = left_depth_mm.at<float>(y0, x0 + 1),
                  z10 = left_depth_mm.at<float>(y0 + 1, x0), z11 = left_depth_mm.at<float>(y0 + 1, x0 + 1);
      if (!(z00 > 0 && z01 > 0 && z10 > 0 && z11 > 0)) continue;
      // Within one surface, the depth of 2x2 neighbours differs by much less
      // than this even on a limb at grazing view (~0.2 mm per px at 200 mm).
      if (std::max({z00, z01, z10, z11}) - std::min({z00, z01, z10, z11}) > 2.0f) continue;
      const double fx = ox - x0, fy = oy - y0;
      const double z = (1 - fy) * ((1 - fx) * z00 + fx * z01) + fy * ((1 - fx) * z10 + fx * z11);
      const Eigen::Vector3d ray_rect((u - g.cx_left_px) / g.focal_px, (v - g.cy_px) / g.focal_px, 1.0);
      const double scale = z / (left_from_rect * ray_rect).z();  // p_rect = scale * ray_rect
      out.at<float>(v, u) = float(g.focal_px * g.baseline_mm / scale - g.disparity_offset_px);
    }
  return out;
}

void RectifyModulePair(const Rig& rig, const ModulePlan& plan, const std::vector<cv::Mat>& images, cv::Mat* left,
                       cv::Mat* right) {
  const StereoModule& mod = rig.module(plan.module);
  cv::remap(images[mod.left_camera], *left, plan.maps.left_fixed, plan.maps.left_frac, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, 0);
  cv::remap(images[mod.right_camera], *right, plan.maps.right_fixed, plan.maps.right_frac, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, 0);
}

FillDiagnosis DiagnoseFill(const Runtime& runtime, int module, const std::vector<cv::Mat>& images,
                           const Reconstruction& rec, const cv::Mat& target_original, const cv::Mat& left_depth_mm) {
  const ModulePlan& plan = runtime.plans()[module];
  const ModuleReport& report = rec.modules[module];
  FillDiagnosis d;
  RectifyModulePair(runtime.rig(), plan, images, &d.left, &d.right);
  d.status = report.status;
  d.match_roi = report.match_roi;
  // The exact float table (the runtime keeps only the fixed-point one).
  cv::Mat left_x, left_y;
  BuildRectifyMap(plan.geometry, runtime.rig().camera(runtime.rig().module(module).left_camera), RectifiedView::kLeft,
                  &left_x, &left_y);
  d.truth_disparity = TruthDisparity(plan, left_x, left_y, left_depth_mm);
  d.target = cv::Mat(plan.geometry.size, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < d.target.rows; ++y)
    for (int x = 0; x < d.target.cols; ++x) {
      const long c = std::lround(left_x.at<float>(y, x)), r = std::lround(left_y.at<float>(y, x));
      if (c >= 0 && r >= 0 && c < target_original.cols && r < target_original.rows &&
          target_original.at<uint8_t>(int(r), int(c)))
        d.target.at<uint8_t>(y, x) = 255;
    }
  const MatchOptions& mo_base = runtime.options().match;
  MatchOptions mo = mo_base;
  mo.roi = report.match_roi;
  mo.min_disparity_px = plan.min_disparity_px;
  mo.num_disparities = plan.num_disparities;
  d.disparity_px = report.match_roi.area() > 0
                       ? Match(d.left, d.right, mo).disparity_px
                       : cv::Mat(plan.geometry.size, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  const RefineAcceptance accept = AcceptanceFor(mo);
  const ObliqueViews oblique(d.left, d.right, report.match_roi.y - 8, report.match_roi.y + report.match_roi.height + 8,
                             ObliqueOptions{});
  d.truth_status = cv::Mat(plan.geometry.size, CV_8UC1, cv::Scalar(0));
  const cv::Mat& t = d.truth_disparity;
  double sum_abs = 0;
  for (int y = 1; y + 1 < d.target.rows; ++y)
    for (int x = 1; x + 1 < d.target.cols; ++x) {
      const float td = t.at<float>(y, x);
      const uint8_t st = d.status.at<uint8_t>(y, x);
      if (st == uint8_t(PixelStatus::kPoint) && std::isfinite(td)) {
        // The runtime's disparity is the second run's (Match is deterministic).
        const float md = d.disparity_px.at<float>(y, x);
        if (std::isfinite(md)) {
          ++d.points_with_truth;
          if (std::abs(md - td) > 1) {
            ++d.points_off_1px;
          } else {
            sum_abs += std::abs(md - td);
          }
        }
      }
      if (!d.target.at<uint8_t>(y, x)) continue;
      const float tl = t.at<float>(y, x - 1), tr = t.at<float>(y, x + 1), tu = t.at<float>(y - 1, x),
                  tb = t.at<float>(y + 1, x);
      const double gx = TruthSlopePx(tl, td, tr), gy = TruthSlopePx(tu, td, tb);
      const auto& edges = FillDiagnosis::kForeshorteningEdges;
      const size_t bin = size_t(std::upper_bound(edges.begin(), edges.end(), 1.0 - gx) - edges.begin());
      ++d.target_px;
      ++d.target_by_foreshortening[bin];
      if (st == uint8_t(PixelStatus::kPoint)) {
        ++d.filled_px;
        ++d.filled_by_foreshortening[bin];
        continue;
      }
      PixelStatus why = PixelStatus::kNoPlane;  // no truth disparity: an edge
      if (std::isfinite(td)) {
        SubpixelResult r;
        why = RefineAndAccept(d.left, d.right, x, y, td, gx, gy, accept, &r);
        if (why == PixelStatus::kPoint && std::abs(r.disparity_px - td) > 0.5) why = PixelStatus::kOffPlane;
      }
      d.truth_status.at<uint8_t>(y, x) = uint8_t(why);
      const bool reachable = why == PixelStatus::kPoint;
      if (st < d.lost.size()) ++d.lost[st][reachable ? 0 : 1];
      if (!reachable) ++d.unreachable_by[size_t(why)];
      if (!reachable && std::isfinite(td)) {
        SubpixelResult r;
        PixelStatus ow;
        const bool tried = oblique.Refine(x, y, td, gx, gy, accept, &r, &ow);
        if (tried && ow == PixelStatus::kPoint && std::abs(r.disparity_px - td) <= 0.5) ++d.unreachable_oblique_ok;
      }
    }
  const int within = d.points_with_truth - d.points_off_1px;
  d.mean_abs_error_px = within > 0 ? sum_abs / within : 0.0;
  d.silhouette = ProfileSilhouetteError(d.disparity_px, d.truth_disparity, d.status, plan.left_valid);
  return d;
}

std::string FillDiagnosis::Summary() const {
  std::string s;
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "fill %.1f%% of %d target px; points off the truth by > 1 px: %d of %d (%.2f%%), "
                "mean |d - truth| of the rest %.3f px\n",
                100.0 * filled_px / std::max(1, target_px), target_px, points_off_1px, points_with_truth,
                100.0 * points_off_1px / std::max(1, points_with_truth), mean_abs_error_px);
  s += buf;
  s += "  lost (% of target): status: reachable from truth / not\n";
  for (size_t k = 0; k < lost.size(); ++k) {
    if (lost[k][0] + lost[k][1] == 0) continue;
    std::snprintf(buf, sizeof buf, "    %-16s %5.2f%% / %5.2f%%\n", PixelStatusName(PixelStatus(k)),
                  100.0 * lost[k][0] / std::max(1, target_px), 100.0 * lost[k][1] / std::max(1, target_px));
    s += buf;
  }
  s += "  by foreshortening 1 - dd/dx: share of target, fill:";
  for (size_t b = 0; b < target_by_foreshortening.size(); ++b) {
    const std::string lo = b == 0 ? "" : std::to_string(kForeshorteningEdges[b - 1]).substr(0, 3);
    const std::string hi = b == kForeshorteningEdges.size() ? "" : std::to_string(kForeshorteningEdges[b]).substr(0, 3);
    std::snprintf(buf, sizeof buf, " [%s,%s) %.1f%% %.0f%%;", lo.c_str(), hi.c_str(),
                  100.0 * target_by_foreshortening[b] / std::max(1, target_px),
                  100.0 * filled_by_foreshortening[b] / std::max(1, target_by_foreshortening[b]));
    s += buf;
  }
  s += "\n  unreachable, by the test failing at the truth:";
  for (size_t k = 0; k < unreachable_by.size(); ++k)
    if (unreachable_by[k]) {
      std::snprintf(buf, sizeof buf, " %s %.2f%%", PixelStatusName(PixelStatus(k)),
                    100.0 * unreachable_by[k] / std::max(1, target_px));
      s += buf;
    }
  std::snprintf(buf, sizeof buf, "\n  unreachable, but reached by the oblique refinement: %.2f%%\n",
                100.0 * unreachable_oblique_ok / std::max(1, target_px));
  return s + buf + "  " + silhouette.Summary();
}

cv::Vec3b DiagnosisColour(PixelStatus status) {
  switch (status) {
    case PixelStatus::kPoint:
      return {60, 160, 60};
    case PixelStatus::kNoSgmMatch:
      return {255, 80, 0};  // blue
    case PixelStatus::kNotDistinct:
      return {255, 0, 255};  // magenta
    case PixelStatus::kLowZncc:
      return {0, 0, 255};  // red
    case PixelStatus::kOffPlane:
    case PixelStatus::kOffPlaneCoarse:
      return {0, 140, 255};  // orange
    case PixelStatus::kNoPlane:
      return {255, 255, 0};  // cyan
    case PixelStatus::kRefineFailed:
      return {0, 255, 255};  // yellow
    case PixelStatus::kSpeckle:
      return {40, 80, 140};  // brown
    case PixelStatus::kLowTexture:
      return {128, 0, 128};  // purple
    case PixelStatus::kOccluded:
      return {128, 128, 128};  // grey
    case PixelStatus::kWrongLine:
      return {180, 105, 255};  // pink
    case PixelStatus::kLeftViewEdge:
      return {64, 64, 64};  // dark grey
    case PixelStatus::kSeenThrough:
      return {0, 0, 128};  // dark red
    case PixelStatus::kSeenThroughSurface:
      return {139, 61, 72};  // dark slate blue
    case PixelStatus::kRightViewEdge:
      return {128, 128, 0};  // teal
    case PixelStatus::kNoGridLine:
      return {0, 128, 128};  // olive
    default:
      return {255, 255, 255};
  }
}

namespace {

std::string Encode(const cv::Mat& image) {
  cv::Mat big;
  cv::resize(image, big, image.size() * 2, 0, 0, cv::INTER_NEAREST);
  STEREORIG_CHECK(big.depth() == CV_8U);
  return EncodePng({uint32_t(big.cols), uint32_t(big.rows), big.channels(), 8, big.data, big.step},
                   1);  // deflate level 1, imwrite's default level (same pixels; imwrite's filter choice differed)
}

}  // namespace

std::vector<std::string> FillDiagnosisImagePaths(const std::string& prefix) {
  return {prefix + "_left.png", prefix + "_status.png", prefix + "_lost.png", prefix + "_error.png"};
}

std::string FillDiagnosisPrefix(const std::string& dir, const std::string& scene, int module) {
  return (std::filesystem::path(dir) / (scene + "_m" + std::to_string(module))).string();
}

std::vector<std::pair<std::string, std::string>> EncodeFillDiagnosisImages(const FillDiagnosis& d,
                                                                           const std::string& prefix) {
  const std::vector<std::string> paths = FillDiagnosisImagePaths(prefix);
  const cv::Rect r = d.match_roi;
  if (r.area() == 0) return {};
  cv::Mat grey = d.left(r).clone();
  cv::Mat status(r.size(), CV_8UC3), lost(r.size(), CV_8UC3), error(r.size(), CV_8UC3);
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const int gx = x + r.x, gy = y + r.y;
      const uint8_t g = grey.at<uint8_t>(y, x);
      const cv::Vec3b dim(g / 3, g / 3, g / 3);
      const bool target = d.target.at<uint8_t>(gy, gx);
      const uint8_t st = d.status.at<uint8_t>(gy, gx);
      status.at<cv::Vec3b>(y, x) = target ? DiagnosisColour(PixelStatus(st))
                                          : (st == uint8_t(PixelStatus::kPoint) ? cv::Vec3b(120, 200, 120) : dim);
      cv::Vec3b l = target ? cv::Vec3b(g / 2, g / 2, g / 2) : dim;
      if (target && st != uint8_t(PixelStatus::kPoint))
        l = d.truth_status.at<uint8_t>(gy, gx) == uint8_t(PixelStatus::kPoint) ? cv::Vec3b(0, 255, 0)
                                                                               : cv::Vec3b(0, 0, 255);
      lost.at<cv::Vec3b>(y, x) = l;
      // |d - truth|: black 0, white >= 0.5 px, red > 1 px (a wrong match).
      const float md = d.disparity_px.at<float>(gy, gx), td = d.truth_disparity.at<float>(gy, gx);
      cv::Vec3b e = target ? cv::Vec3b(60, 30, 30) : cv::Vec3b(0, 0, 0);
      if (std::isfinite(md) && std::isfinite(td) && st == uint8_t(PixelStatus::kPoint)) {
        const float a = std::abs(md - td);
        if (a > 1) {
          e = cv::Vec3b(0, 0, 255);
        } else {
          const uint8_t v = uint8_t(std::min(255.f, a / 0.5f * 255.f));
          e = cv::Vec3b(v, v, v);
        }
      }
      error.at<cv::Vec3b>(y, x) = e;
    }
  return {{paths[0], Encode(grey)}, {paths[1], Encode(status)}, {paths[2], Encode(lost)}, {paths[3], Encode(error)}};
}

}  // namespace stereorig
