#include "datasets/render.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "datasets/rng.h"

namespace stereorig {

double LaserProjector::DistanceToLine(const Eigen::Vector3d& u, int family, int* line) const {
  const double a = family == 0 ? u.x() : u.y();
  const double half = 0.5 * (lines - 1);
  int k = static_cast<int>(std::lround((a / sin_half_fan + 1.0) * half));
  k = std::clamp(k, 0, lines - 1);
  if (line) *line = k;
  return a - sin_half_fan * (k / half - 1.0);
}

bool LaserProjector::InEnvelope(const Eigen::Vector3d& u) const {
  const double edge = sin_half_fan + 2 * sigma;
  return u.z() > 0 && std::abs(u.x()) <= edge && std::abs(u.y()) <= edge;
}

double LaserProjector::Pattern(const Eigen::Vector3d& u) const {
  if (u.z() <= 0) return 0;
  const double reach = sin_half_fan + 4 * sigma;  // the lines end at the fan's edge (soft)
  const double inv2s2 = 0.5 / (sigma * sigma);
  double g = 0;
  for (int family = 0; family < 2; ++family) {
    const double along = family == 0 ? u.y() : u.x();
    if (std::abs(along) > reach) continue;
    const double dist = DistanceToLine(u, family, nullptr);
    double end = 1.0;
    if (std::abs(along) > sin_half_fan) {
      const double e = (std::abs(along) - sin_half_fan);
      end = std::exp(-e * e * inv2s2);
    }
    g += std::exp(-dist * dist * inv2s2) * end;
  }
  return g;
}

std::vector<LaserProjector> MakeProjectors(const SimSpec& spec, const std::vector<Pose>& world_from_projector,
                                           const std::vector<double>& projector_distance_mm) {
  std::vector<LaserProjector> out;
  for (size_t m = 0; m < spec.modules.size(); ++m) {
    const ProjectorSpec& p = spec.modules[m].projector;
    if (!p.enabled || p.power_dn <= 0) continue;
    LaserProjector l;
    l.projector_from_world = world_from_projector[m].Inverse();
    l.origin_world = world_from_projector[m].translation_mm();
    l.sin_half_fan = std::sin(0.5 * p.fan_angle_deg * M_PI / 180.0);
    l.lines = p.lines;
    l.sigma = p.line_sigma_mrad * 1e-3;
    l.power_dn = p.power_dn;
    l.ref_distance_mm = projector_distance_mm[m];
    out.push_back(l);
  }
  return out;
}

namespace {

// Laser light leaving a point (DN), before albedo: every projector that sees it.
double LaserAt(const Scene& scene, const std::vector<LaserProjector>& projectors, const Eigen::Vector3d& p,
               const Eigen::Vector3d& n_vis) {
  double sum = 0;
  for (const LaserProjector& l : projectors) {
    Eigen::Vector3d to = l.origin_world - p;
    const double dist = to.norm();
    to /= dist;
    const double cosi = n_vis.dot(to);
    if (cosi <= 0) continue;
    const Eigen::Vector3d u = l.projector_from_world.rotation() * (-to);
    const double pattern = l.Pattern(u);
    const double r = l.ref_distance_mm / dist;
    const double e = l.power_dn * r * r * cosi * pattern;
    if (e < 1e-3) continue;  // far from every line: skip the shadow ray
    if (scene.Occluded(p, to, 1e-3, dist - 1e-3)) continue;
    sum += e;
  }
  return sum;
}

// Bit k set if projector k's grid envelope covers p (outward normal n_vis,
// turned towards the viewer), p faces it and nothing shadows it.
uint8_t LitBy(const Scene& scene, const std::vector<LaserProjector>& projectors, const Eigen::Vector3d& p,
              const Eigen::Vector3d& n_vis) {
  uint8_t bits = 0;
  for (size_t k = 0; k < projectors.size() && k < 8; ++k) {
    const LaserProjector& l = projectors[k];
    Eigen::Vector3d to = l.origin_world - p;
    const double dist = to.norm();
    to /= dist;
    if (n_vis.dot(to) <= 0) continue;
    if (!l.InEnvelope(l.projector_from_world.rotation() * (-to))) continue;
    if (scene.Occluded(p, to, 1e-3, dist - 1e-3)) continue;
    bits |= uint8_t(1u << k);
  }
  return bits;
}

}  // namespace

SceneRadiance RenderScene(const CameraRays& rays, const Pose& world_from_cam, const Scene& scene,
                          const std::vector<LaserProjector>& projectors, const RenderSpec& render) {
  const int W = rays.width(), H = rays.height();
  SceneRadiance out;
  out.passive = cv::Mat(H, W, CV_32F, cv::Scalar(0));
  out.laser = cv::Mat(H, W, CV_32F, cv::Scalar(0));
  out.depth = cv::Mat(H, W, CV_32F, cv::Scalar(0));
  out.id = cv::Mat(H, W, CV_8U, cv::Scalar(0));
  out.lit = cv::Mat(H, W, CV_8U, cv::Scalar(0));
  const int n = render.samples_per_axis;
  const double inv_n2 = 1.0 / (n * n);
  const Eigen::Matrix3d& R = world_from_cam.rotation();
  const Eigen::Vector3d& o = world_from_cam.translation_mm();
  for (int r = 0; r < H; ++r) {
    float* passive = out.passive.ptr<float>(r);
    float* laser = out.laser.ptr<float>(r);
    float* depth = out.depth.ptr<float>(r);
    uint8_t* id = out.id.ptr<uint8_t>(r);
    uint8_t* lit = out.lit.ptr<uint8_t>(r);
    for (int c = 0; c < W; ++c) {
      if (!rays.PixelValid(c, r)) {
        passive[c] = static_cast<float>(render.background_dn);
        continue;
      }
      SceneHit hit;
      {
        const Eigen::Vector3d v = rays.Ray(c, r, 0.5, 0.5).normalized();
        if (scene.Intersect(o, R * v, 0, 1e9, &hit)) {
          depth[c] = static_cast<float>(hit.t * v.z());
          id[c] = static_cast<uint8_t>(hit.object->id);
          const Eigen::Vector3d d = R * v;
          lit[c] = LitBy(scene, projectors, hit.p_world,
                         hit.n_world.dot(d) > 0 ? Eigen::Vector3d(-hit.n_world) : hit.n_world);
        }
      }
      double sum_passive = 0, sum_laser = 0;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector3d d = (R * rays.Ray(c, r, (i + 0.5) / n, (j + 0.5) / n)).normalized();
          if (!scene.Intersect(o, d, 0, 1e9, &hit)) {
            sum_passive += render.background_dn;
            continue;
          }
          const Eigen::Vector3d n_vis = hit.n_world.dot(d) > 0 ? Eigen::Vector3d(-hit.n_world) : hit.n_world;
          const double albedo = hit.object->Albedo(hit.object->object_from_world * hit.p_world);
          sum_passive += albedo * AmbientIrradianceDn(render, n_vis);
          if (!projectors.empty()) sum_laser += albedo * LaserAt(scene, projectors, hit.p_world, n_vis);
        }
      }
      passive[c] = static_cast<float>(sum_passive * inv_n2);
      laser[c] = static_cast<float>(sum_laser * inv_n2);
    }
  }
  return out;
}

cv::Mat StrayLight(int width, int height, const RenderSpec& render, uint64_t key) {
  Rng rng(key);
  const double angle = rng.Uniform(0, 2 * M_PI);
  const double ax = std::cos(angle), ay = std::sin(angle);
  const double half_diag = 0.5 * std::hypot(width, height);
  cv::Mat out(height, width, CV_32F);
  for (int r = 0; r < height; ++r) {
    float* row = out.ptr<float>(r);
    for (int c = 0; c < width; ++c) {
      const double s = (ax * (c - 0.5 * width) + ay * (r - 0.5 * height)) / half_diag;  // in [-1, 1]
      row[c] = static_cast<float>(render.stray_light_dn * (1.0 + 0.5 * s));
    }
  }
  return out;
}

cv::Mat SpeckleField(int width, int height, const RenderSpec& render, uint64_t key) {
  cv::Mat field(height, width, CV_32F, cv::Scalar(1));
  if (render.speckle_contrast <= 0) return field;
  Rng rng(key);
  cv::Mat g(height, width, CV_32F);
  for (int r = 0; r < height; ++r) {
    float* row = g.ptr<float>(r);
    for (int c = 0; c < width; ++c) row[c] = static_cast<float>(rng.Normal());
  }
  cv::GaussianBlur(g, g, cv::Size(0, 0), render.speckle_grain_px, render.speckle_grain_px, cv::BORDER_REFLECT);
  cv::Scalar mean, stddev;
  cv::meanStdDev(g, mean, stddev);
  const double k = render.speckle_contrast / std::max(1e-12, stddev[0]);
  for (int r = 0; r < height; ++r) {
    const float* in = g.ptr<float>(r);
    float* row = field.ptr<float>(r);
    for (int c = 0; c < width; ++c) row[c] = static_cast<float>(std::max(0.0, 1.0 + k * (in[c] - mean[0])));
  }
  return field;
}

cv::Mat SensorImage(const cv::Mat& radiance_dn, const cv::Mat& stray_dn, const RenderSpec& render, uint64_t key) {
  cv::Mat signal = radiance_dn + stray_dn;
  if (render.psf_sigma_px > 0) {
    cv::GaussianBlur(signal, signal, cv::Size(0, 0), render.psf_sigma_px, render.psf_sigma_px, cv::BORDER_REFLECT);
  }
  cv::Mat out(signal.rows, signal.cols, CV_8U);
  Rng rng(key);
  const double e_per_dn = render.full_well_e / 255.0;
  const double read_dn = render.read_noise_e / e_per_dn;
  for (int r = 0; r < signal.rows; ++r) {
    const float* in = signal.ptr<float>(r);
    uint8_t* o = out.ptr<uint8_t>(r);
    for (int c = 0; c < signal.cols; ++c) {
      double dn = std::max(0.0, static_cast<double>(in[c]));
      if (render.noise) {
        // Shot noise: Poisson in electrons, Gaussian at these counts
        // (> 50 e- wherever it matters); read noise: Gaussian.
        dn += std::sqrt(dn / e_per_dn) * rng.Normal() + read_dn * rng.Normal();
      }
      o[c] = static_cast<uint8_t>(std::clamp(dn, 0.0, 255.0) + 0.5);  // round half up, clip
    }
  }
  return out;
}

}  // namespace stereorig
