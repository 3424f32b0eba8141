// ReadFloatTiff and WriteFloatTiff judged by OpenCV's imread and imwrite
// (another TIFF codec, linked by the tests only): the depth maps written
// before this writer (cv::imwrite) and after it read the same, bit for bit,
// specials included; every refusal is one InputError naming the file, and
// libtiff prints nothing.
#include "calib/core/float_tiff.h"

#include <gtest/gtest.h>

#include <tiffio.h>
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
// cv::imwrite (uncompressed strips of 2 rows: OpenCV 4.6 writes float TIFFs
// uncompressed whatever its compression parameter).
TEST(FloatTiff, ReadsWhatImwriteWrote) {
  const cv::Mat depth = DepthLike(47, 52);
  const std::string path = TempPath("float_tiff_imwrite.tiff");
  ASSERT_TRUE(cv::imwrite(path, depth));
  EXPECT_TRUE(SameBits(AsMat(ReadFloatTiff(path)), depth));
}

// `depth` written by libtiff itself with `compression`, the floating-point
// predictor or none, `mode` "w" (the machine's byte order) or "wb"
// (big-endian), `rows_per_strip` rows a strip: layouts other writers make.
void WriteWithLibtiff(const std::string& path, const cv::Mat& depth, uint16_t compression, uint16_t predictor,
                      const char* mode, uint32_t rows_per_strip) {
  TIFF* tiff = TIFFOpen(path.c_str(), mode);
  ASSERT_NE(tiff, nullptr);
  TIFFSetField(tiff, TIFFTAG_IMAGEWIDTH, uint32_t(depth.cols));
  TIFFSetField(tiff, TIFFTAG_IMAGELENGTH, uint32_t(depth.rows));
  TIFFSetField(tiff, TIFFTAG_BITSPERSAMPLE, 32);
  TIFFSetField(tiff, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP);
  TIFFSetField(tiff, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tiff, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tiff, TIFFTAG_COMPRESSION, compression);
  if (predictor != PREDICTOR_NONE) TIFFSetField(tiff, TIFFTAG_PREDICTOR, predictor);
  TIFFSetField(tiff, TIFFTAG_ROWSPERSTRIP, rows_per_strip);
  for (int y = 0; y < depth.rows; ++y) {  // from a copy: libtiff byte-swaps and predicts in place
    cv::Mat row = depth.row(y).clone();
    ASSERT_EQ(TIFFWriteScanline(tiff, row.data, uint32_t(y), 0), 1);
  }
  TIFFClose(tiff);
}

TEST(FloatTiff, ReadsOtherWritersLayouts) {
  const cv::Mat depth = DepthLike(47, 52);
  const std::string path = TempPath("float_tiff_libtiff.tiff");
  struct Layout {
    uint16_t compression, predictor;
    const char* mode;
    uint32_t rows_per_strip;
  };
  for (const Layout& l :
       {Layout{COMPRESSION_LZW, PREDICTOR_FLOATINGPOINT, "w", 8},
        Layout{COMPRESSION_ADOBE_DEFLATE, PREDICTOR_NONE, "w", 47},
        Layout{COMPRESSION_ADOBE_DEFLATE, PREDICTOR_FLOATINGPOINT, "w", 5},
        // (Big-endian with the floating-point predictor: libtiff 4.5.0 writes
        // samples that it, and so imread, read back as other values.)
        Layout{COMPRESSION_LZW, PREDICTOR_NONE, "wb", 5}, Layout{COMPRESSION_NONE, PREDICTOR_NONE, "wb", 1}}) {
    SCOPED_TRACE(std::to_string(l.compression) + " " + std::to_string(l.predictor) + " " + l.mode);
    WriteWithLibtiff(path, depth, l.compression, l.predictor, l.mode, l.rows_per_strip);
    EXPECT_TRUE(SameBits(AsMat(ReadFloatTiff(path)), depth));
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
  // Damage inside a compressed strip (the directory whole): the row that
  // cannot be decoded is named. The first strip's bytes overwritten.
  const std::string lzw = TempPath("float_tiff_lzw.tiff");
  WriteWithLibtiff(lzw, depth, COMPRESSION_LZW, PREDICTOR_FLOATINGPOINT, "w", 4);
  {
    TIFF* tiff = TIFFOpen(lzw.c_str(), "r");
    ASSERT_NE(tiff, nullptr);
    const uint64_t strip_at = TIFFGetStrileOffset(tiff, 0), strip_bytes = TIFFGetStrileByteCount(tiff, 0);
    TIFFClose(tiff);
    std::fstream f(lzw, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(std::streamoff(strip_at));
    f << std::string(size_t(strip_bytes), '\xff');
  }
  const std::string damaged = RefusalOf(lzw);
  EXPECT_EQ(damaged.find(lzw + ": a TIFF cut short or damaged (row 0 of 40 cannot be read) (libtiff: "), 0u) << damaged;
  EXPECT_EQ(damaged.find('\n'), std::string::npos) << damaged;
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
