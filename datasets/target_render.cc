#include "datasets/target_render.h"

#include <Eigen/Geometry>
#include <cmath>

#include "datasets/render.h"

namespace stereorig {

namespace {

enum Paint : uint8_t { kNone = 0, kWhite = 1, kBlack = 2 };

}  // namespace

double PhysicalBoard::Bow(double x, double y) const {
  if (bow_mm == 0) return 0;
  const Target& t = *target;
  const double cx = 0.5 * (t.min_x_mm() + t.max_x_mm()), cy = 0.5 * (t.min_y_mm() + t.max_y_mm());
  const double r2max = 0.25 * (std::pow(t.max_x_mm() - t.min_x_mm(), 2) + std::pow(t.max_y_mm() - t.min_y_mm(), 2));
  const double r2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
  return bow_mm * (1.0 - r2 / r2max);
}

Eigen::Vector3d PhysicalBoard::TrueCorner(Face face, int id) const {
  const Eigen::Vector3d c = target->CornerInFace(id) * scale;
  const double w = Bow(c.x(), c.y());
  return Eigen::Vector3d(c.x(), c.y(), face == Face::kFront ? -w : w);
}

Eigen::Vector3d PhysicalBoard::TrueCornerInFront(Face face, int id) const {
  const Eigen::Vector3d x = TrueCorner(face, id);
  return face == Face::kFront ? x : true_back_from_front.Inverse() * x;
}

PhysicalBoard MakePhysicalBoard(const Target& target, const CalibrationSpec& spec) {
  PhysicalBoard b;
  b.target = &target;
  b.scale = 1.0 + spec.scale_error_ppm * 1e-6;
  b.bow_mm = spec.nonflatness_mm;
  b.white_albedo = spec.white_albedo;
  b.black_albedo = spec.black_albedo;
  // Misaligned back print: turned and shifted in the back face's plane.
  const Pose misalign(
      Eigen::AngleAxisd(spec.back_misalignment_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
      Eigen::Vector3d(spec.back_misalignment_mm, 0, 0));
  b.true_back_from_front = misalign * target.back_from_front();
  return b;
}

Face FaceSeen(const Pose& world_from_cam, const Pose& world_from_front) {
  const Eigen::Vector3d c_front = world_from_front.Inverse() * world_from_cam.translation_mm();
  return c_front.z() < 0 ? Face::kFront : Face::kBack;
}

cv::Mat RenderTargetRadiance(const CameraRays& rays, const Pose& world_from_cam, const Pose& world_from_front,
                             const PhysicalBoard& board, const RenderSpec& render) {
  const int W = rays.width(), H = rays.height();
  const Face face = board.target->double_sided() ? FaceSeen(world_from_cam, world_from_front) : Face::kFront;
  const Pose front_from_cam = world_from_front.Inverse() * world_from_cam;
  const Pose face_from_cam = face == Face::kFront ? front_from_cam : board.true_back_from_front * front_from_cam;
  const double bow_sign = face == Face::kFront ? -1.0 : 1.0;
  // The face's outward normal (towards its viewer), world frame.
  const Eigen::Vector3d n_world = (world_from_cam * face_from_cam.Inverse()).rotation() * Eigen::Vector3d(0, 0, -1);
  const double e = AmbientIrradianceDn(render, n_world);
  const float value[3] = {static_cast<float>(render.background_dn), static_cast<float>(board.white_albedo * e),
                          static_cast<float>(board.black_albedo * e)};
  const bool faces_camera = !(board.target->double_sided() == false && face_from_cam.translation_mm().z() > 0);
  const Eigen::Matrix3d& R = face_from_cam.rotation();
  const Eigen::Vector3d& o = face_from_cam.translation_mm();
  const double inv_scale = 1.0 / board.scale;

  // Paint along a camera-frame ray v.
  auto paint = [&](const Eigen::Vector3d& v) -> Paint {
    if (!faces_camera) return kNone;
    const Eigen::Vector3d d = R * v;
    if (std::abs(d.z()) < 1e-12) return kNone;
    double z = 0, x = 0, y = 0, t = 0;
    for (int it = 0; it < (board.bow_mm != 0 ? 3 : 1); ++it) {
      t = (z - o.z()) / d.z();
      x = o.x() + t * d.x();
      y = o.y() + t * d.y();
      z = bow_sign * board.Bow(x, y);
    }
    if (t <= 0) return kNone;
    const double xn = x * inv_scale, yn = y * inv_scale;
    if (!board.target->OnPlate(xn, yn)) return kNone;
    return board.target->IsBlack(face, xn, yn) ? kBlack : kWhite;
  };

  std::vector<uint8_t> corner((W + 1) * static_cast<size_t>(H + 1), kNone);
  for (int j = 0; j <= H; ++j) {
    for (int i = 0; i <= W; ++i) {
      if (rays.CornerValid(i, j)) corner[static_cast<size_t>(j) * (W + 1) + i] = paint(rays.Corner(i, j));
    }
  }
  cv::Mat out(H, W, CV_32F);
  const int n = render.edge_samples_per_axis;
  for (int r = 0; r < H; ++r) {
    float* row = out.ptr<float>(r);
    const uint8_t* c0 = &corner[static_cast<size_t>(r) * (W + 1)];
    const uint8_t* c1 = c0 + (W + 1);
    for (int c = 0; c < W; ++c) {
      if (!rays.PixelValid(c, r)) {
        row[c] = value[kNone];
        continue;
      }
      const uint8_t a = c0[c];
      if (a == c0[c + 1] && a == c1[c] && a == c1[c + 1]) {
        row[c] = value[a];
        continue;
      }
      double sum = 0;
      for (int jj = 0; jj < n; ++jj) {
        for (int ii = 0; ii < n; ++ii) sum += value[paint(rays.Ray(c, r, (ii + 0.5) / n, (jj + 0.5) / n))];
      }
      row[c] = static_cast<float>(sum / (n * n));
    }
  }
  return out;
}

int CornersInView(const Camera& camera, const Pose& world_from_cam, const Pose& world_from_front,
                  const PhysicalBoard& board) {
  const Face face = board.target->double_sided() ? FaceSeen(world_from_cam, world_from_front) : Face::kFront;
  const Pose cam_from_front = world_from_cam.Inverse() * world_from_front;
  const Pose cam_from_face =
      face == Face::kFront ? cam_from_front : cam_from_front * board.true_back_from_front.Inverse();
  if (!board.target->double_sided() && cam_from_front.Inverse().translation_mm().z() > 0) return 0;
  int count = 0;
  for (int id = 0; id < board.target->num_corners(); ++id) {
    const Eigen::Vector3d p = cam_from_face * board.TrueCorner(face, id);
    if (p.z() <= 1.0) continue;
    const Eigen::Vector2d q = camera.Project(p);
    if (q.allFinite() && q.x() >= 0 && q.y() >= 0 && q.x() <= camera.imager_width_px() - 1 &&
        q.y() <= camera.imager_height_px() - 1) {
      ++count;
    }
  }
  return count;
}

}  // namespace stereorig
