// scripts/import_stereo_pairs.py turns plain left/right pairs named as
// another tool names them into a dataset the detector reads.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "targets/detect.h"
#include "targets/synthetic_view.h"
#include "targets/target_file.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

TEST(ImportStereoPairs, RenamedPairsAreADatasetTheDetectorReads) {
  const fs::path dir = fs::temp_directory_path() / "stereorig_import_pairs_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "pairs");
  // Two pairs of a plain 9x6 board of 12 mm, named like OpenCV's samples;
  // the right camera sees the board 20 mm further left.
  const Target board = PlainTarget(9, 6, 12.0);
  PinholeCamera camera;  // a small camera keeps the test fast
  camera.fx_px = camera.fy_px = 512;
  camera.cx_px = 187.5;
  camera.cy_px = 145;
  camera.width_px = 376;
  camera.height_px = 291;
  for (int k = 1; k <= 2; ++k) {
    const Pose left_from_face = LookAtFace(board, 300, 10 * k, -15, 5 * k);
    const Pose right_from_face = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-20, 0, 0)) * left_from_face;
    cv::imwrite((dir / "pairs" / ("left0" + std::to_string(k) + ".jpg")).string(),
                RenderFace(board, Face::kFront, camera, left_from_face));
    cv::imwrite((dir / "pairs" / ("right0" + std::to_string(k) + ".jpg")).string(),
                RenderFace(board, Face::kFront, camera, right_from_face));
  }
  const std::string cmd = "/usr/bin/python3 " STEREORIG_SOURCE_DIR "/scripts/import_stereo_pairs.py --left '" +
                          (dir / "pairs" / "left*.jpg").string() + "' --right '" +
                          (dir / "pairs" / "right*.jpg").string() + "' --corners 9x6 --square-mm 12 --out " +
                          (dir / "dataset").string() + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(dir / "dataset" / "layout.yaml"));
  const Target read = ReadTargetFile((dir / "dataset" / "target.yaml").string());
  EXPECT_FALSE(read.double_sided());
  EXPECT_EQ(read.num_corners(), 54);
  const TargetDetector detector(read, DetectOptions());
  for (const char* capture : {"000", "001"}) {
    for (const char* cam : {"cam0.png", "cam1.png"}) {
      const cv::Mat grey = cv::imread((dir / "dataset" / "calibration" / capture / cam).string(), cv::IMREAD_UNCHANGED);
      ASSERT_EQ(grey.type(), CV_8UC1) << capture << "/" << cam;
      const DetectResult r = detector.Detect(grey);
      ASSERT_EQ(r.faces.size(), 1u) << capture << "/" << cam << ": " << r.message;
      EXPECT_EQ(r.faces[0].quality.num_corners, 54);
    }
  }
  // Refuses to overwrite.
  EXPECT_NE(std::system((cmd + " 2>/dev/null").c_str()), 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stereorig
