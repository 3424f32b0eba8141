// EncodePng judged by OpenCV's imread (another decoder, linked by the tests
// only) and by our PngReader: every layout the writers use and the others
// it takes come back byte for byte, padded rows included, at every
// compression level; a layout PNG cannot hold as given is refused.
#include "calib/core/png_writer.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <stdexcept>
#include <string>

#include "calib/core/png_reader.h"

namespace stereorig {
namespace {

PngImage ViewOf(const cv::Mat& m) {
  return {uint32_t(m.cols), uint32_t(m.rows), m.channels(), int(m.elemSize1() * 8), m.data, m.step};
}

std::string WriteFile(const std::string& bytes, const std::string& name) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// Random samples over the whole range (16-bit ones too: a byte order
// swapped on the way would show).
cv::Mat RandomImage(int rows, int cols, int type, uint32_t seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

TEST(EncodePng, EveryLayoutDecodesByteForByteInImreadAndPngReader) {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    for (const int level : {0, 1, 9}) {
      // 1 x 1, odd sizes, and a view into a larger image (rows padded).
      const cv::Mat big = RandomImage(40, 61, type, 7u * type + level);
      for (const cv::Mat& image : {big(cv::Rect(0, 0, 1, 1)), big, big(cv::Rect(3, 5, 37, 23))}) {
        SCOPED_TRACE("type " + std::to_string(type) + ", level " + std::to_string(level) + ", " +
                     std::to_string(image.cols) + " x " + std::to_string(image.rows));
        const std::string path = WriteFile(EncodePng(ViewOf(image), level), "encode_png_test.png");
        const cv::Mat by_opencv = cv::imread(path, cv::IMREAD_UNCHANGED);
        ASSERT_EQ(by_opencv.type(), type);
        ASSERT_EQ(by_opencv.size(), image.size());
        EXPECT_EQ(cv::norm(by_opencv, image, cv::NORM_INF), 0);
        std::optional<PngReader> reader = PngReader::Open(path);
        ASSERT_TRUE(reader);
        cv::Mat by_us(int(reader->height_px()), int(reader->width_px()),
                      CV_MAKETYPE(reader->bit_depth() == 16 ? CV_16U : CV_8U, reader->channels()));
        reader->Read(by_us.data, by_us.step);
        ASSERT_EQ(by_us.type(), type);
        EXPECT_EQ(cv::norm(by_us, image, cv::NORM_INF), 0);
      }
    }
  }
}

// Level 1 (the simulator's captures) deflates a real-looking image: a file
// smaller than its pixels, and level 9 no larger.
TEST(EncodePng, CompressionLevelsDeflate) {
  cv::Mat image(200, 300, CV_8UC1);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) image.at<uint8_t>(y, x) = uint8_t((x / 8 + y / 8) % 2 ? 200 : 30);
  const size_t stored = EncodePng(ViewOf(image), 0).size(), fast = EncodePng(ViewOf(image), 1).size(),
               best = EncodePng(ViewOf(image), 9).size();
  EXPECT_GT(stored, image.total());
  EXPECT_LT(fast, image.total() / 4);
  EXPECT_LE(best, fast);
}

TEST(EncodePng, ALayoutPngCannotHoldIsRefused) {
  const cv::Mat image(4, 5, CV_8UC1, cv::Scalar(9));
  PngImage view = ViewOf(image);
  EXPECT_NO_THROW(EncodePng(view, 1));
  for (const int channels : {0, 2, 5}) {
    PngImage v = view;
    v.channels = channels;
    EXPECT_THROW(EncodePng(v, 1), std::invalid_argument) << channels;
  }
  for (const int bits : {1, 4, 32}) {
    PngImage v = view;
    v.bit_depth = bits;
    EXPECT_THROW(EncodePng(v, 1), std::invalid_argument) << bits;
  }
  PngImage empty = view;
  empty.height_px = 0;
  EXPECT_THROW(EncodePng(empty, 1), std::invalid_argument);
  PngImage too_wide = view;  // libpng's limit, refused before a pixel is read
  too_wide.width_px = PngReader::kMaxSidePx + 1;
  too_wide.row_stride_bytes = too_wide.width_px;
  EXPECT_THROW(EncodePng(too_wide, 1), std::invalid_argument);
  PngImage short_rows = view;
  short_rows.row_stride_bytes = 4;
  EXPECT_THROW(EncodePng(short_rows, 1), std::invalid_argument);
  EXPECT_THROW(EncodePng(view, -1), std::invalid_argument);
  EXPECT_THROW(EncodePng(view, 10), std::invalid_argument);
}

}  // namespace
}  // namespace stereorig
