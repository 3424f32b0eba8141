#include "targets/synthetic_view.h"

#include <cmath>
#include <random>

#include <opencv2/imgproc.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

cv::Mat RenderFace(const Target& target, Face face, const PinholeCamera& camera, const Pose& cam_from_face,
                   const SyntheticViewOptions& options) {
  STEREORIG_CHECK(options.supersample >= 1);
  const int n = options.supersample;
  const Eigen::Matrix3d& r = cam_from_face.rotation();
  const Eigen::Vector3d& t = cam_from_face.translation_mm();
  const Eigen::Vector3d normal_cam = r.col(2);  // face +z in the camera frame
  const double plane_offset = normal_cam.dot(t);
  cv::Mat img(camera.height_px, camera.width_px, CV_32FC1);
  for (int v = 0; v < camera.height_px; ++v) {
    float* row = img.ptr<float>(v);
    for (int u = 0; u < camera.width_px; ++u) {
      double sum = 0;
      for (int sv = 0; sv < n; ++sv) {
        for (int su = 0; su < n; ++su) {
          // Sample positions spread evenly over the pixel's square.
          const double x = u - 0.5 + (su + 0.5) / n, y = v - 0.5 + (sv + 0.5) / n;
          const Eigen::Vector3d d((x - camera.cx_px) / camera.fx_px, (y - camera.cy_px) / camera.fy_px, 1.0);
          const double denom = normal_cam.dot(d);
          double dn = options.background_dn;
          if (std::abs(denom) > 1e-12) {
            const double lambda = plane_offset / denom;
            if (lambda > 0) {
              const Eigen::Vector3d p_face = r.transpose() * (lambda * d - t);
              if (target.OnPlate(p_face.x(), p_face.y())) {
                dn = target.IsBlack(face, p_face.x(), p_face.y()) ? options.black_dn : options.white_dn;
              }
            }
          }
          sum += dn;
        }
      }
      row[u] = static_cast<float>(sum / (n * n));
    }
  }
  if (options.blur_sigma_px > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), options.blur_sigma_px);
  if (options.noise_sigma_dn > 0) {
    std::mt19937_64 rng(options.seed);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(options.noise_sigma_dn));
    for (int v = 0; v < img.rows; ++v)
      for (int u = 0; u < img.cols; ++u) img.at<float>(v, u) += noise(rng);
  }
  cv::Mat out;
  img.convertTo(out, CV_8UC1);  // rounds and saturates
  return out;
}

Pose LookAtFace(const Target& target, double distance_mm, double rx_deg, double ry_deg, double rz_deg,
                const Eigen::Vector2d& shift_mm) {
  const double d2r = M_PI / 180.0;
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(rx_deg * d2r, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(ry_deg * d2r, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rz_deg * d2r, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  const Eigen::Vector3d centre(0.5 * (target.corners_x() - 1) * target.square_size_mm(),
                               0.5 * (target.corners_y() - 1) * target.square_size_mm(), 0.0);
  // p_cam = R (p_face - centre) + (shift, distance)
  return Pose(r, Eigen::Vector3d(shift_mm.x(), shift_mm.y(), distance_mm) - r * centre);
}

}  // namespace stereorig
