#include "reconstruct/pfm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

cv::Mat TestImage() {
  cv::Mat m(3, 4, CV_32FC1);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) m.at<float>(y, x) = 10.0f * y + x + 0.25f;
  m.at<float>(1, 2) = std::numeric_limits<float>::infinity();
  return m;
}

TEST(Pfm, HeaderAndBottomToTopLittleEndianLayout) {
  const std::string bytes = EncodePfm(TestImage());
  const std::string header = "Pf\n4 3\n-1\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 12 * 4);
  // The first stored float is the bottom-left pixel (row 2, col 0) = 20.25,
  // little-endian IEEE 754: 0x41A20000.
  const unsigned char* p = reinterpret_cast<const unsigned char*>(bytes.data() + header.size());
  EXPECT_EQ(p[0], 0x00);
  EXPECT_EQ(p[1], 0x00);
  EXPECT_EQ(p[2], 0xA2);
  EXPECT_EQ(p[3], 0x41);
}

TEST(Pfm, RoundTripKeepsEveryBitAndInf) {
  const cv::Mat m = TestImage();
  const cv::Mat back = DecodePfm(EncodePfm(m), "mem");
  ASSERT_EQ(back.size(), m.size());
  EXPECT_EQ(std::memcmp(back.data, m.data, 12 * 4), 0);
  EXPECT_TRUE(std::isinf(back.at<float>(1, 2)));
}

TEST(Pfm, BigEndianFilesAreRead) {
  cv::Mat m(1, 1, CV_32FC1, cv::Scalar(20.25f));
  const std::string bytes = std::string("Pf\n1 1\n1.0\n") + std::string("\x41\xA2\x00\x00", 4);
  EXPECT_EQ(DecodePfm(bytes, "mem").at<float>(0, 0), 20.25f);
}

// Independent implementation: OpenCV's own PFM codec reads what we write and
// writes what we read.
TEST(Pfm, AgreesWithOpenCvCodec) {
  const auto dir = std::filesystem::temp_directory_path() / ("pfm_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string ours = (dir / "ours.pfm").string(), theirs = (dir / "theirs.pfm").string();
  const cv::Mat m = TestImage();
  WritePfm(m, ours);
  const cv::Mat by_opencv = cv::imread(ours, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(by_opencv.type(), CV_32FC1);
  ASSERT_EQ(by_opencv.size(), m.size());
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(by_opencv.at<float>(y, x), m.at<float>(y, x)) << y << "," << x;
  ASSERT_TRUE(cv::imwrite(theirs, m));
  const cv::Mat by_us = ReadPfm(theirs);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(by_us.at<float>(y, x), m.at<float>(y, x)) << y << "," << x;
  std::filesystem::remove_all(dir);
}

TEST(Pfm, MalformedInputIsAnInputError) {
  EXPECT_THROW(DecodePfm("P5\n1 1\n255\n", "x"), InputError);
  EXPECT_THROW(DecodePfm("Pf\n2 2\n-1\n1234", "x"), InputError);  // short data
  EXPECT_THROW(DecodePfm("Pf\n2 x\n-1\n", "x"), InputError);
  EXPECT_THROW(DecodePfm("Pf\n1 1\n0\n0000", "x"), InputError);
  EXPECT_THROW(ReadPfm("/nonexistent/file.pfm"), InputError);
}

}  // namespace
}  // namespace stereorig
