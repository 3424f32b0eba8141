// The simulator's calibration images against two implementations it does not
// share: OpenCV's findChessboardCornersSB finds the corners in the rendered
// (noise-free) images, and python3-mrcal projects the true 3D corners with
// the true camera (exported as a .cameramodel). Both use the same pixel
// convention: (0,0) is the centre of the top-left pixel.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/core/cameramodel_export.h"
#include "datasets/camera_rays.h"
#include "datasets/render.h"
#include "datasets/sim_spec.h"
#include "datasets/target_render.h"

namespace stereorig {
namespace {

const std::string kPython = "/usr/bin/python3";  // Debian's, which has python3-mrcal
const std::string kScript = std::string(STEREORIG_SOURCE_DIR) + "/tests/reference/mrcal_project.py";

std::vector<Eigen::Vector2d> MrcalProject(const Camera& cam, const std::vector<Eigen::Vector3d>& p_cam,
                                          const std::string& tag) {
  const std::string dir = ::testing::TempDir();
  const std::string model = dir + "/sim_" + tag + ".cameramodel", in = dir + "/sim_" + tag + "_p.txt",
                    out = dir + "/sim_" + tag + "_q.txt";
  WriteCameramodel(cam, Pose::Identity(), model);
  {
    std::ofstream f(in);
    f.precision(17);
    for (const Eigen::Vector3d& p : p_cam) f << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  const std::string cmd = kPython + " " + kScript + " model " + model + " " + in + " " + out + " > /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream f(out);
  std::vector<Eigen::Vector2d> q;
  double x, y;
  while (f >> x >> y) q.emplace_back(x, y);
  return q;
}

// Renders two tilted poses in cam0 (front face) and cam3 (back face) and
// returns the RMS distance of OpenCV's corners to python3-mrcal's projection
// of the TRUE corners; *nominal_shift_px gets the RMS distance between the
// true corners' and the nominal (perfect board) corners' projections.
double CornerRms(const CalibrationSpec& calibration, double* nominal_shift_px) {
  SimSpec spec = DefaultSimSpec();
  spec.render.noise = false;
  spec.calibration = calibration;
  const SpecRig rig = BuildSpecRig(spec);
  const Target target = DefaultTarget();
  const PhysicalBoard board = MakePhysicalBoard(target, spec.calibration);
  const PhysicalBoard perfect = MakePhysicalBoard(target, CalibrationSpec());
  double shift2 = 0;
  const Eigen::Vector3d center_front(0.5 * (target.corners_x() - 1) * target.square_size_mm(),
                                     0.5 * (target.corners_y() - 1) * target.square_size_mm(), 0);
  // Two poses, tilted as an operator would; the whole board in view of every camera.
  const std::vector<Eigen::Vector3d> tilts_deg = {{20, -15, 10}, {-25, 30, -20}};
  double sum2 = 0;
  Eigen::Vector2d sum_e = Eigen::Vector2d::Zero();
  int n = 0;
  for (int cam_index : {0, 3}) {  // module 0 sees the front face, module 1 the back
    const Camera& cam = rig.sim.rig.camera(cam_index);
    const Pose& world_from_cam = rig.world_from_camera[cam_index];
    const CameraRays rays(cam, 2);
    for (size_t k = 0; k < tilts_deg.size(); ++k) {
      const Eigen::Vector3d a = tilts_deg[k] * M_PI / 180.0;
      const Eigen::Matrix3d r =
          (Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(a.z(), Eigen::Vector3d::UnitZ()))
              .toRotationMatrix();
      // The board's centre on the camera's axis, 230 mm away: all of it in view.
      const Eigen::Vector3d c = world_from_cam * Eigen::Vector3d(0, 0, 230);
      const Pose world_from_front(r, c - r * center_front);
      const cv::Mat radiance = RenderTargetRadiance(rays, world_from_cam, world_from_front, board, spec.render);
      const cv::Mat image = SensorImage(radiance, cv::Mat::zeros(radiance.size(), CV_32F), spec.render, 1);
      cv::imwrite(::testing::TempDir() + "/sim_board_" + std::to_string(k) + "_" + std::to_string(cam_index) + ".png",
                  image);
      std::vector<cv::Point2f> found;
      const bool ok = cv::findChessboardCornersSB(image, cv::Size(target.corners_x(), target.corners_y()), found,
                                                  cv::CALIB_CB_ACCURACY);
      EXPECT_TRUE(ok) << "pose " << k << " camera " << cam_index;
      EXPECT_EQ(static_cast<int>(found.size()), target.num_corners());
      if (!ok || static_cast<int>(found.size()) != target.num_corners()) return 1e9;

      const Face face = FaceSeen(world_from_cam, world_from_front);
      EXPECT_EQ(face, cam_index < 2 ? Face::kFront : Face::kBack);
      const Pose cam_from_front = world_from_cam.Inverse() * world_from_front;
      const Pose cam_from_face =
          face == Face::kFront ? cam_from_front : cam_from_front * board.true_back_from_front.Inverse();
      std::vector<Eigen::Vector3d> p_cam;
      const Pose cam_from_face_perfect =
          face == Face::kFront ? cam_from_front : cam_from_front * perfect.true_back_from_front.Inverse();
      for (int id = 0; id < target.num_corners(); ++id) {
        p_cam.push_back(cam_from_face * board.TrueCorner(face, id));
        shift2 += (cam.Project(p_cam.back()) - cam.Project(cam_from_face_perfect * perfect.TrueCorner(face, id)))
                      .squaredNorm();
      }
      const std::vector<Eigen::Vector2d> expected =
          MrcalProject(cam, p_cam, std::to_string(k) + "_" + std::to_string(cam_index));
      EXPECT_EQ(expected.size(), p_cam.size());
      if (expected.size() != p_cam.size()) return 1e9;
      // OpenCV's corner order may start at either end: match each found
      // corner to its nearest expected one (squares are ~40 px apart).
      for (const cv::Point2f& f : found) {
        double best = 1e9;
        Eigen::Vector2d e = Eigen::Vector2d::Zero();
        for (const Eigen::Vector2d& q : expected) {
          const Eigen::Vector2d d(f.x - q.x(), f.y - q.y());
          if (d.norm() < best) best = d.norm(), e = d;
        }
        EXPECT_LT(best, 1.0);
        sum2 += e.squaredNorm();
        sum_e += e;
        ++n;
      }
    }
  }
  const double rms = std::sqrt(sum2 / n);
  *nominal_shift_px = std::sqrt(shift2 / n);
  std::printf("%d corners: RMS %.4f px, mean (%.4f, %.4f) px; true vs perfect board: %.3f px RMS\n", n, rms,
              sum_e.x() / n, sum_e.y() / n, *nominal_shift_px);
  EXPECT_LT((sum_e / n).norm(), 0.03);  // no half-pixel convention slip, no systematic shift
  return rms;
}

// Noise off: what is left is the detector's own sub-pixel error and the
// renderer's anti-aliasing (8x8 samples on edge pixels, 1/64 px steps).
TEST(SimChessboard, OpenCvFindsCornersWhereMrcalProjectsThem) {
  double shift = 0;
  EXPECT_LT(CornerRms(CalibrationSpec(), &shift), 0.05);
  EXPECT_EQ(shift, 0.0);
}

// An imperfect board (scale error, misaligned back print, bow) is rendered
// where its TRUE corners are, which lie well away from the nominal ones.
TEST(SimChessboard, ImperfectBoardIsRenderedWhereItsTrueCornersAre) {
  CalibrationSpec c;
  c.scale_error_ppm = 3000;  // 0.3 mm over the 99 mm board
  c.back_misalignment_deg = 0.3;
  c.back_misalignment_mm = 0.3;
  c.nonflatness_mm = 0.5;
  double shift = 0;
  EXPECT_LT(CornerRms(c, &shift), 0.05);
  EXPECT_GT(shift, 0.5);  // the knobs move the corners by far more than the tolerance
}

}  // namespace
}  // namespace stereorig
