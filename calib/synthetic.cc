#include "calib/synthetic.h"

#include <cmath>

namespace stereorig {

TargetGeometry DefaultTestTarget() {
  TargetGeometry t;
  t.corners_x = 9;
  t.corners_y = 7;
  t.square_size_mm = 12.0;
  t.double_sided = true;
  // The back grid behind the front one, turned over about y: the back's
  // corner 0 sits behind the front's last column; 3 mm of board between.
  t.back_from_front = Pose(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                           Eigen::Vector3d((t.corners_x - 1) * t.square_size_mm, 0.0, 3.0));
  t.back_from_front_sigma << 0.05, 0.05, 0.05, 0.05, 0.05, 0.05;
  return t;
}

SyntheticData ObserveBoards(const Rig& rig, const TargetGeometry& target, const std::vector<Pose>& ref_from_front,
                            const TrueCornerInFront& true_corner_in_front, const SyntheticOptions& o) {
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_px);
  SyntheticData out;
  CalibrationInput& in = out.input;
  in.target = target;
  in.source = "synthetic seed " + std::to_string(o.seed);
  for (int c = 0; c < rig.num_cameras(); ++c) {
    in.cameras.push_back({rig.camera_names()[c], rig.camera(c).imager_width_px(), rig.camera(c).imager_height_px()});
  }
  for (const StereoModule& m : rig.modules()) in.modules.push_back({m.name, m.left_camera, m.right_camera, {}});
  out.ref_from_front = ref_from_front;
  for (int c = 0; c < static_cast<int>(ref_from_front.size()); ++c) {
    const Pose& ref_from_board = ref_from_front[c];
    const Eigen::Vector3d normal_ref = ref_from_board.rotation().col(2);  // front face's z: away from its viewers
    const Eigen::Vector3d& origin_ref = ref_from_board.translation_mm();
    for (int cam = 0; cam < rig.num_cameras(); ++cam) {
      const Pose cam_from_ref = rig.CamFromReference(cam);
      const Eigen::Vector3d cam_centre_ref = cam_from_ref.Inverse().translation_mm();
      const Face face = (cam_centre_ref - origin_ref).dot(normal_ref) < 0 ? Face::kFront : Face::kBack;
      if (face == Face::kBack && !target.double_sided) continue;
      const Camera& camera = rig.camera(cam);
      BoardObservation obs{c, cam, face, {}, {}};
      for (int id = 0; id < target.num_corners(); ++id) {
        const Eigen::Vector3d p_cam = cam_from_ref * (ref_from_board * true_corner_in_front(face, id));
        if (p_cam.z() <= 0) continue;
        Eigen::Vector2d q = camera.Project(p_cam);
        q += Eigen::Vector2d(noise(rng), noise(rng));
        if (q.x() < o.edge_margin_px || q.y() < o.edge_margin_px ||
            q.x() > camera.imager_width_px() - 1 - o.edge_margin_px ||
            q.y() > camera.imager_height_px() - 1 - o.edge_margin_px) {
          continue;
        }
        obs.corner_ids.push_back(id);
        obs.q_px.push_back(q);
      }
      if (static_cast<int>(obs.corner_ids.size()) >= o.min_corners) in.observations.push_back(std::move(obs));
    }
  }
  return out;
}

SyntheticData MakeSyntheticCaptures(const Rig& rig, const TargetGeometry& target, const Pose& true_bff,
                                    const Pose& ref_from_volume, const SyntheticOptions& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double s = target.square_size_mm;
  const Eigen::Vector3d centre_in_front(0.5 * (target.corners_x - 1) * s, 0.5 * (target.corners_y - 1) * s, 0.0);
  const double deg = M_PI / 180.0;
  std::vector<Pose> ref_from_front;
  for (int c = 0; c < o.num_captures; ++c) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(o.max_roll_deg * deg * u(rng), Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(o.max_tilt_deg * deg * u(rng), Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(o.max_tilt_deg * deg * u(rng), Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    const Eigen::Vector3d t(o.lateral_mm * u(rng), o.lateral_mm * u(rng), o.depth_mm * u(rng));
    ref_from_front.push_back(ref_from_volume * Pose(R, t) * Pose(Eigen::Matrix3d::Identity(), -centre_in_front));
  }
  const Pose front_from_back = true_bff.Inverse();
  SyntheticOptions observe = o;
  observe.seed = o.seed + 7919;  // the noise draws, apart from the pose draws
  SyntheticData data = ObserveBoards(
      rig, target, ref_from_front,
      [&](Face face, int id) {
        const Eigen::Vector3d x = target.CornerInFace(id);
        return face == Face::kFront ? x : front_from_back * x;
      },
      observe);
  data.input.source = "synthetic seed " + std::to_string(o.seed);
  return data;
}

std::vector<Eigen::Vector3d> VolumePoints(const Pose& ref_from_volume, const Eigen::Vector3d& half, int n,
                                          unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i)
    p.push_back(ref_from_volume * Eigen::Vector3d(half.x() * u(rng), half.y() * u(rng), half.z() * u(rng)));
  return p;
}

}  // namespace stereorig
