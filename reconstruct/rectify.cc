#include "reconstruct/rectify.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

Eigen::Vector3d RectifiedGeometry::PixelAndDisparity(const Eigen::Vector3d& p_rect) const {
  const double u = focal_px * p_rect.x() / p_rect.z() + cx_left_px;
  const double v = focal_px * p_rect.y() / p_rect.z() + cy_px;
  return {u, v, focal_px * baseline_mm / p_rect.z() - disparity_offset_px};
}

Eigen::Vector3d RectifiedGeometry::Triangulate(double u_px, double v_px, double d_img_px) const {
  const double z = focal_px * baseline_mm / (d_img_px + disparity_offset_px);
  const Eigen::Vector3d p_rect((u_px - cx_left_px) * z / focal_px, (v_px - cy_px) * z / focal_px, z);
  return rect_from_left.transpose() * p_rect;
}

RectifiedGeometry ComputeRectification(const Camera& left, const Camera& right, const Pose& right_from_left,
                                       const Eigen::Vector3d& look_at_left_mm, const RectificationNames& names) {
  RectifiedGeometry g;
  const Eigen::Matrix3d& r = right_from_left.rotation();
  const Eigen::Vector3d right_centre_left = -r.transpose() * right_from_left.translation_mm();
  g.baseline_mm = right_centre_left.norm();
  if (!(g.baseline_mm > 0))
    throw InputError(names.rig, names.module + ": its cameras share one centre (zero baseline)");
  const Eigen::Vector3d e1 = right_centre_left / g.baseline_mm;
  const Eigen::Vector3d mean_axis = (Eigen::Vector3d::UnitZ() + r.transpose() * Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Vector3d e2 = mean_axis.cross(e1);
  if (e2.norm() < 1e-6) throw InputError(names.rig, names.module + ": its baseline lies along its optical axes");
  e2.normalize();
  const Eigen::Vector3d e3 = e1.cross(e2);
  g.rect_from_left.row(0) = e1.transpose();
  g.rect_from_left.row(1) = e2.transpose();
  g.rect_from_left.row(2) = e3.transpose();
  g.right_from_rect = r * g.rect_from_left.transpose();
  g.focal_px = std::min(0.5 * (left.fx() + left.fy()), 0.5 * (right.fx() + right.fy()));
  g.size = cv::Size(left.imager_width_px(), left.imager_height_px());
  const Eigen::Vector3d c = g.rect_from_left * look_at_left_mm;
  if (!(c.z() > 0)) {
    // "Behind" alone misled where the centre lies far to the side (x 5000
    // mm at z 200 mm is 91 deg off a verged module's axis): the angle says
    // which, the view's half width what would be in front. atan2 and hypot:
    // a centre 1e300 mm away squared to inf in norm().
    const double off_deg = std::atan2(std::hypot(c.x(), c.y()), c.z()) * 180 / M_PI;
    const double half_view_deg = std::atan(0.5 * g.size.width / g.focal_px) * 180 / M_PI;
    char where[160];
    std::snprintf(
        where, sizeof where,
        "it lies %.0f deg off the module's viewing direction (%s; its view reaches about %.0f deg either side)",
        off_deg, off_deg >= 135 ? "behind it" : "to its side", half_view_deg);
    const std::string given = names.volume_key + (names.volume_value.empty() ? "" : " " + names.volume_value);
    throw InputError(names.options,
                     "the measurement volume's centre (" + given + ") is not in front of " + names.module + ": " +
                         (c != Eigen::Vector3d::Zero() ? std::string(where) : "it is at its left camera's centre") +
                         "; check " + names.volume_key + (names.also_check.empty() ? "" : ", or " + names.also_check));
  }
  // Centre pixel of the image ((W-1)/2 in mrcal's pixel-centre convention).
  g.cx_left_px = 0.5 * (g.size.width - 1) - g.focal_px * c.x() / c.z();
  g.cy_px = 0.5 * (g.size.height - 1) - g.focal_px * c.y() / c.z();
  // In the right rectified frame the centre is at x - B; put it at the
  // image centre too.
  const double cx_right = 0.5 * (g.size.width - 1) - g.focal_px * (c.x() - g.baseline_mm) / c.z();
  g.disparity_offset_px = std::round(cx_right - g.cx_left_px);  // whole px: keeps d_img integer-aligned
  return g;
}

void BuildRectifyMap(const RectifiedGeometry& g, const Camera& cam, RectifiedView view, cv::Mat* map_x,
                     cv::Mat* map_y) {
  const int w = g.size.width, h = g.size.height;
  const bool left = view == RectifiedView::kLeft;
  const Eigen::Matrix3d cam_from_rect = left ? g.rect_from_left.transpose() : g.right_from_rect;
  const double cx = left ? g.cx_left_px : g.cx_left_px + g.disparity_offset_px;
  *map_x = cv::Mat(h, w, CV_32FC1);
  *map_y = cv::Mat(h, w, CV_32FC1);
  Eigen::Matrix<double, Eigen::Dynamic, 3> rays(w, 3);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d ray_rect((u - cx) / g.focal_px, (v - g.cy_px) / g.focal_px, 1.0);
      rays.row(u) = (cam_from_rect * ray_rect).transpose();
    }
    const Eigen::Matrix<double, Eigen::Dynamic, 2> q = cam.ProjectMany(rays);
    float* px = map_x->ptr<float>(v);
    float* py = map_y->ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const bool ok = rays(u, 2) > 0 && std::isfinite(q(u, 0)) && std::isfinite(q(u, 1));
      px[u] = ok ? float(q(u, 0)) : -1.f;
      py[u] = ok ? float(q(u, 1)) : -1.f;
    }
  }
}

RectifyMaps BuildRectifyMaps(const RectifiedGeometry& g, const Camera& left, const Camera& right) {
  RectifyMaps maps;
  cv::Mat x, y;
  BuildRectifyMap(g, left, RectifiedView::kLeft, &x, &y);
  cv::convertMaps(x, y, maps.left_fixed, maps.left_frac, CV_16SC2);
  BuildRectifyMap(g, right, RectifiedView::kRight, &x, &y);
  cv::convertMaps(x, y, maps.right_fixed, maps.right_frac, CV_16SC2);
  return maps;
}

}  // namespace stereorig
