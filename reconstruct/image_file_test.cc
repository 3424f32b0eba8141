// ReadImageFile against libpng (through OpenCV) on PNGs built here byte by
// byte, interlaced or not, of several sizes, bit depths and colour types:
// where libpng decodes the image data, the checked reader passes it (one
// byte too many, or bytes after the stream: with libpng's warning line);
// where it is one byte short (libpng: "Not enough image data"), the reader
// names the file in one line and libpng prints nothing. An independent check of
// the image data's size (calib/core/png_image_data.h), Adam7's passes above
// all.
#include "reconstruct/image_file.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "calib/core/input_error.h"
#include "calib/core/png_file.h"
#include "calib/core/png_image_data.h"

namespace stereorig {
namespace {

std::string BigEndian32(uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

std::string Chunk(const std::string& type, const std::string& data) {
  return BigEndian32(uint32_t(data.size())) + type + data + BigEndian32(PngCrc(type + data));
}

// A PNG whose image data is `num_bytes` of rows, every filter byte 0 (none)
// and the pixels a ramp, deflated by zlib, then `trailing` (bytes after the
// deflate stream's end, in the same IDAT).
std::string Png(uint32_t width_px, uint32_t height_px, int bit_depth, int colour_type, bool interlaced,
                uint64_t num_bytes, const std::string& trailing = "") {
  std::string raw(num_bytes, '\0');
  for (size_t i = 0; i < raw.size(); ++i) raw[i] = char(i % 251);
  // Filter bytes 0: the rows' first bytes, pass by pass. Simplest to set
  // each to 0 by walking the rows as libpng will.
  static constexpr int kX0[7] = {0, 4, 0, 2, 0, 1, 0}, kDx[7] = {8, 8, 4, 4, 2, 2, 1};
  static constexpr int kY0[7] = {0, 0, 4, 0, 2, 0, 1}, kDy[7] = {8, 8, 8, 4, 4, 2, 2};
  const int channels = colour_type == 2 ? 3 : colour_type == 6 ? 4 : 1;
  size_t at = 0;
  for (int p = 0; p < (interlaced ? 7 : 1); ++p) {
    const uint32_t x0 = interlaced ? kX0[p] : 0, dx = interlaced ? kDx[p] : 1;
    const uint32_t y0 = interlaced ? kY0[p] : 0, dy = interlaced ? kDy[p] : 1;
    const uint64_t w = width_px > x0 ? (width_px - x0 + dx - 1) / dx : 0;
    const uint64_t h = height_px > y0 ? (height_px - y0 + dy - 1) / dy : 0;
    if (w == 0) continue;
    for (uint64_t r = 0; r < h; ++r, at += 1 + (w * bit_depth * channels + 7) / 8)
      if (at < raw.size()) raw[at] = 0;
  }
  uLongf size = compressBound(uLong(raw.size()));
  std::string idat(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(idat.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                      uLong(raw.size()), 9),
            Z_OK);
  idat.resize(size);
  idat += trailing;
  const std::string ihdr = BigEndian32(width_px) + BigEndian32(height_px) +
                           std::string{char(bit_depth), char(colour_type), 0, 0, char(interlaced)};
  return std::string("\x89PNG\r\n\x1a\n", 8) + Chunk("IHDR", ihdr) + Chunk("IDAT", idat) + Chunk("IEND", "");
}

cv::Mat Decode(const std::string& png) {
  return cv::imdecode(std::vector<uchar>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
}

std::string Write(const std::string& bytes) {
  const std::string path = ::testing::TempDir() + "/image_file_test.png";
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(ReadImageFile, PassesWhatLibpngDecodesAndNamesImageDataOneByteShort) {
  struct Format {
    int bit_depth, colour_type, cv_type;
  };
  const Format formats[] = {{8, 0, CV_8UC1}, {1, 0, CV_8UC1}, {16, 0, CV_16UC1}, {8, 2, CV_8UC3}, {8, 6, CV_8UC4}};
  const cv::Size sizes[] = {{1, 1}, {3, 2}, {8, 8}, {13, 7}, {42, 23}, {5, 17}};
  int cases = 0;
  for (const Format& f : formats)
    for (const cv::Size& s : sizes)
      for (const bool interlaced : {false, true}) {
        const std::string what = std::to_string(s.width) + "x" + std::to_string(s.height) + " bit depth " +
                                 std::to_string(f.bit_depth) + " colour type " + std::to_string(f.colour_type) +
                                 (interlaced ? " interlaced" : "");
        const int channels = f.colour_type == 2 ? 3 : f.colour_type == 6 ? 4 : 1;
        const uint64_t n = PngImageDataBytes(s.width, s.height, f.bit_depth, channels, interlaced);
        const std::string whole = Png(s.width, s.height, f.bit_depth, f.colour_type, interlaced, n);
        const cv::Mat by_libpng = Decode(whole);
        ASSERT_FALSE(by_libpng.empty()) << what;  // libpng takes exactly n bytes
        EXPECT_EQ(by_libpng.size(), s) << what;
        EXPECT_EQ(by_libpng.type(), f.cv_type) << what;
        ::testing::internal::CaptureStderr();
        const cv::Mat ours = ReadImageFile(Write(whole));
        EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << what;
        EXPECT_EQ(cv::norm(ours, by_libpng, cv::NORM_INF), 0) << what;

        const std::string short_one = Png(s.width, s.height, f.bit_depth, f.colour_type, interlaced, n - 1);
        ::testing::internal::CaptureStderr();
        EXPECT_TRUE(Decode(short_one).empty()) << what;  // libpng refuses n - 1 bytes ...
        EXPECT_NE(::testing::internal::GetCapturedStderr().find("libpng error"), std::string::npos) << what;
        ::testing::internal::CaptureStderr();
        try {  // ... and so do we, in our one line, before libpng could
          ReadImageFile(Write(short_one));
          ADD_FAILURE() << what << ": passed";
        } catch (const InputError& e) {
          EXPECT_EQ(e.problem(), "a damaged PNG (its image data inflates to " + std::to_string(n - 1) +
                                     " bytes; its IHDR's " + std::to_string(s.width) + " x " +
                                     std::to_string(s.height) + " px image needs " + std::to_string(n) + ")")
              << what;
        }
        EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << what;

        // One byte too many, and bytes after the stream's end: libpng reads
        // the image whole with a warning, and so do we, the warning its.
        const std::pair<std::string, std::string> extras[] = {
            {Png(s.width, s.height, f.bit_depth, f.colour_type, interlaced, n + 1),
             "libpng warning: IDAT: Too much image data\n"},
            {Png(s.width, s.height, f.bit_depth, f.colour_type, interlaced, n, "junk"),
             "libpng warning: IDAT: Extra compressed data\n"}};
        for (const auto& [png, warning] : extras) {
          ::testing::internal::CaptureStderr();
          const cv::Mat by_libpng_too = Decode(png);
          EXPECT_EQ(::testing::internal::GetCapturedStderr(), warning) << what;
          EXPECT_EQ(by_libpng_too.size(), s) << what;
          ::testing::internal::CaptureStderr();
          try {
            const cv::Mat read = ReadImageFile(Write(png));
            EXPECT_EQ(read.size(), s) << what;
            EXPECT_EQ(read.type(), f.cv_type) << what;
            if (read.size() == s && read.type() == f.cv_type) {  // the n bytes' image: the extra is ignored
              EXPECT_EQ(cv::norm(read, by_libpng, cv::NORM_INF), 0) << what;
            }
          } catch (const InputError& e) {
            ADD_FAILURE() << what << ": " << e.what();
          }
          EXPECT_EQ(::testing::internal::GetCapturedStderr(), warning) << what;
        }
        ++cases;
      }
  EXPECT_EQ(cases, 60);
}

}  // namespace
}  // namespace stereorig
