#include "reconstruct/synthetic_scene.h"

#include <cmath>
#include <random>

namespace stereorig {

std::vector<cv::Mat> RenderSphereCapture(const Rig& rig, const SphereSceneSpec& s) {
  struct Projector {
    Eigen::Vector3d centre;  // reference frame
    Eigen::Matrix3d proj_from_ref;
  };
  std::vector<Projector> projectors;
  for (int m = 0; m < rig.num_modules(); ++m) {
    const Pose left_from_right = rig.module(m).right_from_left.Inverse();
    const Pose ref_from_module = rig.S(0, m);
    projectors.push_back(
        {ref_from_module * (0.5 * left_from_right.translation_mm()), ref_from_module.rotation().transpose()});
  }
  const double ca = std::cos(s.grid_angle_deg * M_PI / 180), sa = std::sin(s.grid_angle_deg * M_PI / 180);
  const double fan = std::tan(s.fan_half_angle_deg * M_PI / 180);
  auto line_profile = [&](double a) {  // a in projector tangent units
    const double k = std::round(a / s.period_rad);
    const double d = a - k * s.period_rad;
    return std::exp(-d * d / (2 * s.line_sigma_rad * s.line_sigma_rad));
  };
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> noise(0, s.noise_sigma_dn);
  std::vector<cv::Mat> images;
  for (int k = 0; k < rig.num_cameras(); ++k) {
    const Camera& cam = rig.camera(k);
    const Pose cam_from_ref = rig.CamFromReference(k);
    const Pose ref_from_cam = cam_from_ref.Inverse();
    const Eigen::Vector3d eye = ref_from_cam.translation_mm();
    cv::Mat img(cam.imager_height_px(), cam.imager_width_px(), CV_8UC1, cv::Scalar(0));
    // Only pixels inside the sphere's image: bound it by projecting points
    // of its silhouette's bounding cube.
    double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d c =
          s.centre_mm + s.radius_mm * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
      const Eigen::Vector2d q = cam.Project(cam_from_ref * c);
      u0 = std::min(u0, q.x()), u1 = std::max(u1, q.x()), v0 = std::min(v0, q.y()), v1 = std::max(v1, q.y());
    }
    const int x0 = std::max(0, int(u0) - 2), x1 = std::min(img.cols - 1, int(u1) + 2);
    const int y0 = std::max(0, int(v0) - 2), y1 = std::min(img.rows - 1, int(v1) + 2);
    for (int y = y0; y <= y1; ++y) {
      Eigen::Matrix<double, Eigen::Dynamic, 2> q(x1 - x0 + 1, 2);
      for (int x = x0; x <= x1; ++x) q.row(x - x0) << x, y;
      const Eigen::Matrix<double, Eigen::Dynamic, 3> v = cam.UnprojectMany(q);
      for (int x = x0; x <= x1; ++x) {
        if (!v.row(x - x0).allFinite()) continue;
        const Eigen::Vector3d dir = (ref_from_cam.rotation() * v.row(x - x0).transpose()).normalized();
        const Eigen::Vector3d oc = eye - s.centre_mm;
        const double b = oc.dot(dir), c = oc.squaredNorm() - s.radius_mm * s.radius_mm;
        const double disc = b * b - c;
        if (disc < 0) continue;
        const double t = -b - std::sqrt(disc);
        if (t <= 0) continue;
        const Eigen::Vector3d p = eye + t * dir;
        const Eigen::Vector3d n = (p - s.centre_mm) / s.radius_mm;
        const double albedo = 1.0 + s.texture_contrast * (0.6 * std::sin(0.35 * p.x() + 0.2 * p.z()) +
                                                          0.4 * std::sin(0.27 * p.y() - 0.31 * p.x() + 1.0));
        // Lambertian: the same radiance towards every camera (diffuse light from -y).
        double radiance = s.ambient_dn * (0.6 + 0.4 * std::max(0.0, -n.y()));
        if (s.laser_on) {
          for (const Projector& pr : projectors) {
            const Eigen::Vector3d to_proj = pr.centre - p;
            const double cosi = n.dot(to_proj.normalized());
            if (cosi <= 0) continue;  // the sphere is convex: facing = visible
            const Eigen::Vector3d pp = pr.proj_from_ref * (p - pr.centre);
            if (pp.z() <= 0) continue;
            const double a = pp.x() / pp.z(), bb = pp.y() / pp.z();
            if (std::abs(a) > fan || std::abs(bb) > fan) continue;
            const double ar = ca * a + sa * bb, br = -sa * a + ca * bb;
            radiance += s.laser_dn * cosi * std::min(1.0, line_profile(ar) + line_profile(br));
          }
        }
        img.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(std::lround(albedo * radiance + noise(rng)));
      }
    }
    images.push_back(img);
  }
  return images;
}

std::vector<Eigen::Vector3d> SampleSphere(const Eigen::Vector3d& centre, double r, double spacing) {
  // Fibonacci lattice: near-uniform spacing.
  const int n = std::max(100, int(4 * M_PI * r * r / (spacing * spacing)));
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(n);
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - 2 * (i + 0.5) / n, rr = std::sqrt(1 - z * z), phi = golden * i;
    pts.push_back(centre + r * Eigen::Vector3d(rr * std::cos(phi), rr * std::sin(phi), z));
  }
  return pts;
}

}  // namespace stereorig
