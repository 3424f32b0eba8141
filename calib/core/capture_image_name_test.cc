#include "calib/core/capture_image_name.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

TEST(CaptureImageName, ReadsTheCameraIndexOfCamKPng) {
  EXPECT_EQ(CameraIndexOfImageName("cam0.png"), 0);
  EXPECT_EQ(CameraIndexOfImageName("cam12.png"), 12);
  EXPECT_EQ(CameraIndexOfImageName("cam999999.png"), 999999);
  EXPECT_EQ(CameraImageName(3), "cam3.png");
  EXPECT_EQ(CameraIndexOfImageName(CameraImageName(41)), 41);
}

// More digits than any rig (or an int) holds: beyond any rig, not an
// exception from std::stoi (check's scan used to throw std::out_of_range).
TEST(CaptureImageName, AHugeIndexIsBeyondAnyRig) {
  EXPECT_EQ(CameraIndexOfImageName("cam1000000.png"), kCameraIndexBeyondAnyRig);
  EXPECT_EQ(CameraIndexOfImageName("cam99999999999999999999.png"), kCameraIndexBeyondAnyRig);
}

// Leading zeros: no reader opens cam007.png (camera 7's image is
// cam7.png), so it is not a capture image.
TEST(CaptureImageName, OtherNamesAreNotCaptureImages) {
  for (const char* name :
       {"cam.png", "cam0.PNG", "cam-1.png", "cam+1.png", "cam 1.png", "xcam0.png", "cam0.png.tmp", "Cam0.png", "cam0",
        "cam0png", ".png", "cam1a.png", "cam007.png", "cam00.png", "cam0000001.png"})
    EXPECT_FALSE(CameraIndexOfImageName(name).has_value()) << name;
}

}  // namespace
}  // namespace stereorig
