#include "reconstruct/free_space.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

std::vector<std::vector<uint8_t>> FreeSpaceRefuted(const std::vector<FreeSpaceView>& views,
                                                   const std::vector<PointCloud>& clouds,
                                                   const FreeSpaceOptions& options) {
  STEREORIG_CHECK(views.size() == clouds.size());
  const int nm = int(views.size());
  std::vector<std::vector<uint8_t>> refuted(nm);
  for (int j = 0; j < nm; ++j) refuted[j].assign(clouds[j].size(), 0);
  const float none = -std::numeric_limits<float>::infinity();
  for (int j = 0; j < nm; ++j) {
    if (clouds[j].size() == 0) continue;
    const FreeSpaceView& view = views[j];
    const RectifiedGeometry& g = view.geometry;
    // rect_from_reference: the rectified left frame of module j.
    const Eigen::Matrix3d r = g.rect_from_left * view.module_from_reference.rotation();
    const Eigen::Vector3d t = g.rect_from_left * view.module_from_reference.translation_mm();
    const Eigen::Vector3f eye = view.camera_centre_reference_mm.cast<float>();
    auto project = [&](const Eigen::Vector3f& p, int* u, int* v, float* d) {
      const Eigen::Vector3d p_rect = r * p.cast<double>() + t;
      if (!(p_rect.z() > 1e-6)) return false;
      const Eigen::Vector3d q = g.PixelAndDisparity(p_rect);
      *u = int(std::lround(q.x())), *v = int(std::lround(q.y()));
      *d = float(q.z());
      return *u >= 0 && *v >= 0 && *u < g.size.width && *v < g.size.height;
    };
    // The depth buffer of the other modules' points that face camera j.
    cv::Mat buffer;  // CV_32FC1, rectified left size: the largest disparity, -inf = none
    for (int k = 0; k < nm; ++k) {
      if (k == j) continue;
      const PointCloud& c = clouds[k];
      for (size_t i = 0; i < c.size(); ++i) {
        const Eigen::Vector3f to_eye = eye - c.xyz_mm[i];
        const float dist = to_eye.norm();
        if (!(c.normal[i].dot(to_eye) > float(options.min_facing_cos) * dist)) continue;
        int u, v;
        float d;
        if (!project(c.xyz_mm[i], &u, &v, &d)) continue;
        if (buffer.empty()) buffer = cv::Mat(g.size, CV_32FC1, cv::Scalar(none));
        float& b = buffer.at<float>(v, u);
        if (d > b) b = d;
      }
    }
    if (buffer.empty()) continue;
    const int rad = options.window_radius_px;
    // The steepest slope a facing surface has in j's image, px/px at depth
    // Z: B / Z * tan(acos(min_facing_cos)).
    const double cos_max = std::max(options.min_facing_cos, 0.05);
    const double tan_max = std::sqrt(1 - cos_max * cos_max) / cos_max;
    const PointCloud& c = clouds[j];
    for (size_t i = 0; i < c.size(); ++i) {
      const Eigen::Vector3d p_rect = r * c.xyz_mm[i].cast<double>() + t;
      if (!(p_rect.z() > 1e-6)) continue;
      const Eigen::Vector3d q = g.PixelAndDisparity(p_rect);
      const int u = int(std::lround(q.x())), v = int(std::lround(q.y()));
      if (u < 0 || v < 0 || u >= g.size.width || v >= g.size.height) continue;
      // P's own surface, its normal's plane n.X = h (rectified frame), in
      // j's image: d = B (n_x (u - cx) + n_y (v - cy) + n_z f) / h, so the
      // disparity steps by B n_x / h and B n_y / h per px. A correct point
      // of another module on the same surface, one or two px away, differs
      // by that step, not by the margin. Clamped to the steepest facing slope.
      const Eigen::Vector3d n_rect = r * c.normal[i].cast<double>();
      const double h = n_rect.dot(p_rect);
      const double max_slope = g.baseline_mm / p_rect.z() * tan_max;
      double sx = 0, sy = 0;
      if (std::abs(h) > 1e-9) {
        sx = std::clamp(g.baseline_mm * n_rect.x() / h, -max_slope, max_slope);
        sy = std::clamp(g.baseline_mm * n_rect.y() / h, -max_slope, max_slope);
      }
      int support = 0;
      for (int y = std::max(0, v - rad); y <= std::min(g.size.height - 1, v + rad); ++y) {
        const float* b = buffer.ptr<float>(y);
        for (int x = std::max(0, u - rad); x <= std::min(g.size.width - 1, u + rad); ++x) {
          const double front = q.z() + sx * (x - q.x()) + sy * (y - q.y()) + options.margin_px;
          support += b[x] > front;
        }
      }
      refuted[j][i] = support >= options.min_support;
    }
  }
  return refuted;
}

}  // namespace stereorig
