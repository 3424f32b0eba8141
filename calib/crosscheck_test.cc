// Stage 1 against independent implementations on the same detections:
// OpenCV's calibrateCamera (its default 5-coefficient model = mrcal's
// OPENCV5, our default) and Debian's mrcal-calibrate-cameras (fed a corners
// cache). Our residual RMS must not
// exceed theirs, and our projection must agree with mrcal's within our
// reported 1-sigma uncertainty.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "calib/calib_test_util.h"
#include "calib/intrinsics.h"

namespace stereorig {
namespace {

TEST(Crosscheck, Stage1AgainstOpencvAndMrcalCalibrateCameras) {
  // Boards kept near camera 0's optical axis, 200 mm away (+-10 mm), so that
  // most views are whole.
  const SimulatedRig rig = MakeDefaultRig();
  SyntheticOptions o;
  o.seed = 9;
  o.num_captures = 30;
  o.lateral_mm = 10.0;
  o.depth_mm = 20.0;
  const TargetGeometry target = DefaultTestTarget();
  const SyntheticData data = MakeSyntheticCaptures(rig.rig, target, target.back_from_front,
                                                   Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 200)), o);
  const CalibrationInput& in = data.input;
  const int cam = 0;
  // mrcal-calibrate-cameras is made for whole boards (mrgingham finds only
  // those); on this set's partial views its seeding falls into a local
  // minimum (4.4 px RMS, measured). So all three run on the whole-board views.
  std::vector<const BoardObservation*> views;
  for (const BoardObservation* v : testing::ViewsOf(in, cam))
    if (static_cast<int>(v->corner_ids.size()) == in.target.num_corners()) views.push_back(v);
  std::printf("%zu whole-board views\n", views.size());
  ASSERT_GE(views.size(), 10u);
  const IntrinsicsResult ours =
      CalibrateIntrinsics(cam, in.cameras[cam], in.target, views, IntrinsicsOptions(), "test");

  // OpenCV: its RMS is sqrt(sum |e|^2 / Npoints) (2D); ours is per coordinate.
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img;
  for (const BoardObservation* v : views) {
    obj.emplace_back();
    img.emplace_back();
    for (size_t k = 0; k < v->corner_ids.size(); ++k) {
      const Eigen::Vector3d p = in.target.CornerInFace(v->corner_ids[k]);
      obj.back().emplace_back(p.x(), p.y(), 0.f);
      img.back().emplace_back(v->q_px[k].x(), v->q_px[k].y());
    }
  }
  cv::Mat K, dist;
  std::vector<cv::Mat> rv, tv;
  const double opencv_rms_2d =
      cv::calibrateCamera(obj, img, cv::Size(752, 582), K, dist, rv, tv, 0,
                          cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, DBL_EPSILON));
  const double opencv_rms = opencv_rms_2d / std::sqrt(2.0);
  std::printf("stage 1 rms: ours %.8f px, OpenCV %.8f px (per coordinate)\n", ours.report.rms_px, opencv_rms);
  // Both minimise the same unregularised sum of squares of the same model
  // (ours ends with an unregularised solve, see SolveFinal), and no corner
  // is an outlier at this noise, so ours must not be worse than OpenCV's.
  EXPECT_EQ(ours.report.num_outliers, 0);
  EXPECT_LE(ours.report.rms_px, opencv_rms);

  // mrcal-calibrate-cameras on a corners cache of the same detections.
  const std::string dir = ::testing::TempDir() + "/mrcal_cc";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  {
    std::ofstream f(dir + "/corners.vnl");
    f << "# filename x y level\n";
    for (const BoardObservation* v : views) {
      char name[64];
      std::snprintf(name, sizeof name, "cam0-%03d.png", v->capture);
      std::vector<std::string> rows(in.target.num_corners(), std::string(name) + " - - -");
      for (size_t k = 0; k < v->corner_ids.size(); ++k) {
        char b[128];
        std::snprintf(b, sizeof b, "%s %.17g %.17g 0", name, v->q_px[k].x(), v->q_px[k].y());
        rows[v->corner_ids[k]] = b;
      }
      for (const auto& r : rows) f << r << "\n";
    }
  }
  const std::string cmd = "cd " + dir +
                          " && /usr/bin/python3 /usr/bin/mrcal-calibrate-cameras --corners-cache corners.vnl "
                          "--lensmodel LENSMODEL_OPENCV5 --focal 1000 --imagersize 752 582 --object-spacing 12 "
                          "--object-width-n 9 --object-height-n 7 --skip-calobject-warp-solve --outdir . "
                          "'cam0-*.png' > log.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string ref = dir + "/ref.txt";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + std::string(STEREORIG_SOURCE_DIR) +
                         "/calib/testdata/mrcal_model_rms.py " + dir + "/camera-0.cameramodel > " + ref)
                            .c_str()),
            0);
  std::ifstream f(ref);
  double mrcal_rms;
  int mrcal_outliers;
  ASSERT_TRUE(f >> mrcal_rms >> mrcal_outliers);
  std::vector<double> intr;
  double x;
  while (f >> x) intr.push_back(x);
  ASSERT_EQ(intr.size(), 9u);
  std::printf("stage 1 rms: ours %.8f px, mrcal-calibrate-cameras %.8f px\n", ours.report.rms_px, mrcal_rms);
  EXPECT_EQ(mrcal_outliers, 0);
  // mrcal-calibrate-cameras keeps its distortion regularisation in the final
  // solve, which costs it a little RMS; ours drops it for OPENCV5.
  EXPECT_LE(ours.report.rms_px, mrcal_rms);
  // Projection at the image centre (200 mm away) of the three solutions.
  const Eigen::Vector2d qc = ours.report.uncertainty[0].q_px;
  const double sigma_c = ours.report.uncertainty[0].rms_stdev_px;
  Eigen::Vector3d v;
  ASSERT_TRUE(ours.camera.Unproject(qc, &v));
  const Eigen::Vector3d p = v * 200.0;
  // OpenCV minimises the same unregularised sum of squares of the same model:
  // the same optimum, so the same projection to well within our 1 sigma.
  std::vector<cv::Point2d> q_cv;
  cv::projectPoints(std::vector<cv::Point3d>{{p.x(), p.y(), p.z()}}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist,
                    q_cv);
  const double dq_opencv = (Eigen::Vector2d(q_cv[0].x, q_cv[0].y) - qc).norm();
  // mrcal-calibrate-cameras regularises the distortions towards 0 and the
  // centre pixel towards the imager's middle, which pulls its solution a
  // little (measured 1.6 sigma here); its own uncertainty does not include
  // that pull, so it agrees within 2 of our sigma, not 1.
  const Camera theirs("LENSMODEL_OPENCV5", intr, 752, 582);
  const double dq_mrcal = (theirs.Project(p) - qc).norm();
  std::printf(
      "projection difference at the centre: OpenCV %.5f px, mrcal-calibrate-cameras %.5f px; our 1 sigma %.5f px\n",
      dq_opencv, dq_mrcal, sigma_c);
  EXPECT_LT(dq_opencv, 0.1 * sigma_c);
  EXPECT_LT(dq_mrcal, 2.0 * sigma_c);
}

}  // namespace
}  // namespace stereorig
