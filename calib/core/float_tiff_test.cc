// ReadFloatTiff and WriteFloatTiff judged by OpenCV's imread and imwrite
// (another TIFF codec, linked by the tests only): the depth maps written
// before this writer (cv::imwrite) and after it read the same, bit for bit,
// specials included; every refusal is one InputError naming the file, and
// libtiff prints nothing.
#include "calib/core/float_tiff.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

std::string TempPath(const std::string& name) { return ::testing::TempDir() + "/" + name; }

// A depth map's values and every special a float can hold (0 = no surface,
// NaN, infinities, a denormal, the extremes).
cv::Mat DepthLike(int rows, int cols) {
  cv::Mat m(rows, cols, CV_32FC1);
  cv::RNG rng(11);
  rng.fill(m, cv::RNG::UNIFORM, 150.0, 260.0);
  const float specials[] = {0.0f,
                            -0.0f,
                            std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            std::numeric_limits<float>::denorm_min(),
                            std::numeric_limits<float>::max(),
                            std::numeric_limits<float>::lowest()};
  for (size_t i = 0; i < std::size(specials); ++i) m.at<float>(int(i) % rows, int(i * 7) % cols) = specials[i];
  return m;
}

bool SameBits(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y)
    if (std::memcmp(a.ptr(y), b.ptr(y), a.cols * a.elemSize()) != 0) return false;
  return true;
}

cv::Mat AsMat(const FloatImage& image) {
  return cv::Mat(int(image.height_px), int(image.width_px), CV_32FC1, const_cast<float*>(image.values.data())).clone();
}

TEST(FloatTiff, WrittenFilesReadInImreadAndBack) {
  const cv::Mat big = DepthLike(61, 83);
  for (const cv::Mat& depth : {big, big(cv::Rect(5, 3, 41, 29)), big(cv::Rect(0, 0, 1, 1))}) {
    const std::string path = TempPath("float_tiff_test.tiff");
    WriteFloatTiff(path, depth.cols, depth.rows, depth.ptr<float>(), depth.step);
    EXPECT_TRUE(SameBits(cv::imread(path, cv::IMREAD_UNCHANGED), depth));
    EXPECT_TRUE(SameBits(AsMat(ReadFloatTiff(path)), depth));
  }
}

// Datasets simulated before this reader wrote their depth maps with
// cv::imwrite (uncompressed); OpenCV's other compressions read too.
TEST(FloatTiff, ReadsWhatImwriteWrote) {
  const cv::Mat depth = DepthLike(47, 52);
  for (const int compression : {1, 5, 8, 32946}) {  // none, LZW, Adobe deflate, deflate
    const std::string path = TempPath("float_tiff_imwrite.tiff");
    ASSERT_TRUE(cv::imwrite(path, depth, {cv::IMWRITE_TIFF_COMPRESSION, compression})) << compression;
    EXPECT_TRUE(SameBits(AsMat(ReadFloatTiff(path)), depth)) << compression;
  }
}

std::string RefusalOf(const std::string& path) {
  ::testing::internal::CaptureStderr();
  std::string what;
  try {
    ReadFloatTiff(path);
    what = "read";
  } catch (const InputError& e) {
    what = e.what();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << path;
  return what;
}

TEST(FloatTiff, AnotherKindOrADamagedFileIsNamedInOneLine) {
  const std::string grey = TempPath("float_tiff_grey.tiff");
  ASSERT_TRUE(cv::imwrite(grey, cv::Mat(8, 9, CV_8UC1, cv::Scalar(3))));
  EXPECT_EQ(RefusalOf(grey), grey +
                                 ": a TIFF of 1 channel(s) of 8-bit integer samples; only float32 single-channel "
                                 "TIFFs are read (depth maps)");
  const std::string colour = TempPath("float_tiff_colour.tiff");
  ASSERT_TRUE(cv::imwrite(colour, cv::Mat(8, 9, CV_16UC3, cv::Scalar(1, 2, 3))));
  EXPECT_EQ(RefusalOf(colour), colour +
                                   ": a TIFF of 3 channel(s) of 16-bit integer samples; only float32 single-channel "
                                   "TIFFs are read (depth maps)");
  const cv::Mat depth = DepthLike(40, 50);
  const std::string whole = TempPath("float_tiff_whole.tiff");
  WriteFloatTiff(whole, depth.cols, depth.rows, depth.ptr<float>(), depth.step);
  std::ifstream f(whole, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(f)), {});
  // Cut in its pixels (the directory, written last, is at the end: cut
  // there, the header points past the file).
  for (const size_t keep : {size_t(8), size_t(4000), bytes.size() / 2, bytes.size() - 10}) {
    const std::string cut = TempPath("float_tiff_cut.tiff");
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, keep);
    const std::string what = RefusalOf(cut);
    EXPECT_EQ(what.find(cut + ": "), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  const std::string text = TempPath("float_tiff_text.tiff");
  std::ofstream(text) << "not a TIFF\n";
  EXPECT_EQ(RefusalOf(text).find(text + ": cannot be read as a TIFF file (libtiff: "), 0u);
}

TEST(FloatTiff, AFolderThatIsNotThereIsNamed) {
  const std::string path = TempPath("no_such_folder/depth.tiff");
  const float pixel = 1;
  ::testing::internal::CaptureStderr();
  try {
    WriteFloatTiff(path, 1, 1, &pixel, sizeof pixel);
    ADD_FAILURE() << "written";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find(path + ": cannot write the TIFF file"), 0u) << e.what();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(FloatTiff, StartsAsTiffKnowsBothByteOrders) {
  EXPECT_TRUE(StartsAsTiff(std::string("II*\0rest", 8)));
  EXPECT_TRUE(StartsAsTiff(std::string("MM\0*rest", 8)));
  EXPECT_TRUE(StartsAsTiff(std::string("II+\0", 4)));
  EXPECT_FALSE(StartsAsTiff("\x89PNG\r\n\x1a\n"));
  EXPECT_FALSE(StartsAsTiff("II"));
}

}  // namespace
}  // namespace stereorig
