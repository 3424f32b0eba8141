// ReadImageFile decodes a PNG as imread(IMREAD_UNCHANGED) does, byte for
// byte: on PNGs built here byte by byte in every colour type and bit depth
// PNG defines, with and without a tRNS chunk, interlaced or not, of several
// sizes; and on real files, written by libpng's encoder (cv::imwrite) and
// the ones in docs/images. Where the image data is one byte short, it names
// the file in one line; where it holds more than the image, it reads it as
// libpng does; either way nothing of libpng's reaches stderr, where imread
// prints "libpng error: Not enough image data" or "libpng warning: IDAT:
// Too much image data".
#include "reconstruct/image_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "calib/core/input_error.h"
#include "calib/core/png_testing.h"
#include "reconstruct/grey_image.h"

namespace stereorig {
namespace {

using testing::Chunk;
using testing::Deflate;
using testing::Ihdr;
using testing::kPngSignature;

// A PNG format: bit depth, colour type, and a tRNS chunk or none.
struct Format {
  int bit_depth, colour_type;
  bool trns;
  int cv_type;  // imread's
};

int SamplesPerPixel(int colour_type) {
  switch (colour_type) {
    case 2:
      return 3;
    case 4:
      return 2;
    case 6:
      return 4;
    default:
      return 1;  // grey, palette index
  }
}

// The image data of a width x height image in `f`, raw: for each row (each
// of Adam7's seven passes' rows if interlaced) a filter byte, 0 (none), and
// the row's packed samples, a ramp; palette indices kept below the 5 of
// Png's PLTE.
std::string RawImageData(uint32_t width_px, uint32_t height_px, const Format& f, bool interlaced) {
  static constexpr int kX0[7] = {0, 4, 0, 2, 0, 1, 0}, kDx[7] = {8, 8, 4, 4, 2, 2, 1};
  static constexpr int kY0[7] = {0, 0, 4, 0, 2, 0, 1}, kDy[7] = {8, 8, 8, 4, 4, 2, 2};
  std::string raw;
  for (int p = 0; p < (interlaced ? 7 : 1); ++p) {
    const uint32_t x0 = interlaced ? kX0[p] : 0, dx = interlaced ? kDx[p] : 1;
    const uint32_t y0 = interlaced ? kY0[p] : 0, dy = interlaced ? kDy[p] : 1;
    const uint64_t w = width_px > x0 ? (width_px - x0 + dx - 1) / dx : 0;
    const uint64_t h = height_px > y0 ? (height_px - y0 + dy - 1) / dy : 0;
    if (w == 0) continue;  // an empty pass has no rows
    const uint64_t row_bytes = (w * f.bit_depth * SamplesPerPixel(f.colour_type) + 7) / 8;
    for (uint64_t r = 0; r < h; ++r) {
      raw += '\0';
      for (uint64_t i = 0; i < row_bytes; ++i) {
        const size_t n = raw.size();
        if (f.colour_type == 3 && f.bit_depth == 8) {
          raw += char(n % 5);
        } else if (f.colour_type == 3 && f.bit_depth == 4) {
          raw += "\x01\x23\x40\x14"[n % 4];  // two indices a byte
        } else {
          raw += char(n * 7);  // 1- and 2-bit indices are below 4
        }
      }
    }
  }
  return raw;
}

// A PNG of `f` whose IDAT holds `raw` deflated, then `trailing` (bytes after
// the deflate stream's end).
std::string Png(uint32_t width_px, uint32_t height_px, const Format& f, bool interlaced, const std::string& raw,
                const std::string& trailing = "") {
  std::string chunks = Chunk("IHDR", Ihdr(width_px, height_px, f.bit_depth, f.colour_type, interlaced));
  if (f.colour_type == 3) chunks += Chunk("PLTE", "\x10\x20\x30\x40\x50\x60\x70\x80\x90\xa0\xb0\xc0\xd0\xe0\xf0");
  if (f.trns) {
    if (f.colour_type == 3) chunks += Chunk("tRNS", std::string("\0\x80\xff", 3));  // 3 of 5 entries
    if (f.colour_type == 0) chunks += Chunk("tRNS", std::string("\0\x07", 2));      // grey 7
    if (f.colour_type == 2) chunks += Chunk("tRNS", std::string("\0\x07\0\x08\0\x09", 6));
  }
  return kPngSignature + chunks + Chunk("IDAT", Deflate(raw, 9) + trailing) + Chunk("IEND", "");
}

std::string Write(const std::string& bytes, const std::string& name = "image_file_test.png") {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// ReadImageFile(path) and imread(path, IMREAD_UNCHANGED) give the same Mat,
// byte for byte, and ours prints nothing.
void ExpectAsImread(const std::string& path, const std::string& what) {
  const cv::Mat by_imread = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(by_imread.empty()) << what;
  ::testing::internal::CaptureStderr();
  cv::Mat ours;
  try {
    ours = ReadImageFile(path);
  } catch (const InputError& e) {
    ADD_FAILURE() << what << ": " << e.what();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << what;
  ASSERT_EQ(ours.type(), by_imread.type()) << what;
  ASSERT_EQ(ours.size(), by_imread.size()) << what;
  EXPECT_EQ(cv::norm(ours, by_imread, cv::NORM_INF), 0) << what;
}

TEST(ReadImageFile, DecodesEveryPngFormatAsImreadDoesAndNamesImageDataOneByteShort) {
  const Format formats[] = {
      {1, 0, false, CV_8UC1}, {2, 0, false, CV_8UC1},   {4, 0, false, CV_8UC1},  {8, 0, false, CV_8UC1},
      {8, 0, true, CV_8UC1},  {16, 0, false, CV_16UC1}, {16, 0, true, CV_16UC1}, {8, 2, false, CV_8UC3},
      {8, 2, true, CV_8UC4},  {16, 2, false, CV_16UC3}, {16, 2, true, CV_16UC4}, {1, 3, false, CV_8UC3},
      {4, 3, false, CV_8UC3}, {8, 3, false, CV_8UC3},   {8, 3, true, CV_8UC4},   {2, 3, true, CV_8UC4},
      {8, 4, false, CV_8UC4}, {16, 4, false, CV_16UC4}, {8, 6, false, CV_8UC4},  {16, 6, false, CV_16UC4}};
  const cv::Size sizes[] = {{1, 1}, {3, 2}, {8, 8}, {13, 7}, {42, 23}, {5, 17}};
  int cases = 0;
  for (const Format& f : formats)
    for (const cv::Size& s : sizes)
      for (const bool interlaced : {false, true}) {
        const std::string what = std::to_string(s.width) + "x" + std::to_string(s.height) + " bit depth " +
                                 std::to_string(f.bit_depth) + " colour type " + std::to_string(f.colour_type) +
                                 (f.trns ? " with tRNS" : "") + (interlaced ? " interlaced" : "");
        const std::string raw = RawImageData(s.width, s.height, f, interlaced);
        const std::string path = Write(Png(s.width, s.height, f, interlaced, raw));
        ExpectAsImread(path, what);
        EXPECT_EQ(cv::imread(path, cv::IMREAD_UNCHANGED).type(), f.cv_type) << what;

        // One byte short: imread prints libpng's error; we refuse, silently.
        const std::string short_one = Write(Png(s.width, s.height, f, interlaced, raw.substr(0, raw.size() - 1)));
        ::testing::internal::CaptureStderr();
        EXPECT_TRUE(cv::imread(short_one, cv::IMREAD_UNCHANGED).empty()) << what;
        EXPECT_EQ(::testing::internal::GetCapturedStderr(), "libpng error: Not enough image data\n") << what;
        ::testing::internal::CaptureStderr();
        try {
          ReadImageFile(short_one);
          ADD_FAILURE() << what << ": read";
        } catch (const InputError& e) {
          EXPECT_EQ(e.what(), short_one +
                                  ": a damaged PNG (its image data ends before the image does: Not enough "
                                  "image data)")
              << what;
        }
        EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << what;

        // One byte too many, and bytes after the stream's end: imread reads
        // the image whole with libpng's warning, and so do we, without it.
        ExpectAsImread(Write(Png(s.width, s.height, f, interlaced, raw + "x")), what + ", a byte too many");
        ExpectAsImread(Write(Png(s.width, s.height, f, interlaced, raw, "junk")), what + ", bytes after the stream");
        ++cases;
      }
  EXPECT_EQ(cases, 20 * 6 * 2);
}

// A palette index past the PLTE's entries: an encoder's fault, which libpng
// warns of and decodes (black), as imread does.
TEST(ReadImageFile, APaletteIndexPastThePaletteDecodesAsInImread) {
  const Format f{8, 3, false, CV_8UC3};
  std::string raw = RawImageData(13, 7, f, false);
  raw[5] = char(200);
  ExpectAsImread(Write(Png(13, 7, f, false, raw)), "palette index 200 of 5");
}

// Real files: written by libpng's encoder (cv::imwrite, its filters and
// compression levels), and the grey images in docs/images, as the
// simulator's captures are.
TEST(ReadImageFile, DecodesRealFilesAsImreadDoes) {
  cv::Mat pattern(291, 376, CV_8UC1);
  cv::randu(pattern, 0, 256);
  for (int y = 0; y < pattern.rows; y += 2) pattern.row(y) = cv::Scalar(y % 256);  // runs that deflate well
  cv::Mat colour, wide;
  cv::merge(std::vector<cv::Mat>{pattern, 255 - pattern, pattern / 2}, colour);
  pattern.convertTo(wide, CV_16U, 257.0);
  cv::Mat alpha;
  cv::merge(std::vector<cv::Mat>{colour, pattern}, alpha);
  const std::pair<std::string, cv::Mat> images[] = {
      {"grey", pattern}, {"colour", colour}, {"16-bit", wide}, {"bgra", alpha}};
  for (const auto& [name, image] : images)
    for (const int level : {0, 1, 6, 9}) {
      const std::string path = ::testing::TempDir() + "/image_file_test_real.png";
      ASSERT_TRUE(cv::imwrite(path, image, {cv::IMWRITE_PNG_COMPRESSION, level}));
      ExpectAsImread(path, name + " at compression " + std::to_string(level));
    }
  int docs = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(STEREORIG_SOURCE_DIR) + "/docs/images"))
    if (e.path().extension() == ".png") {
      ExpectAsImread(e.path().string(), e.path().string());
      ++docs;
    }
  EXPECT_GE(docs, 3);
}

// A float32 TIFF (the truth maps' depth) is read, by libtiff; any other
// format is refused in one line, OpenCV's decoders (and their messages on
// stderr) not being linked: a BMP OpenCV would have read, a JPEG.
TEST(ReadImageFile, FloatTiffsAreReadAndOtherFormatsRefused) {
  const std::string path = ::testing::TempDir() + "/image_file_test.tiff";
  const cv::Mat depth(23, 42, CV_32FC1, cv::Scalar(206.5f));
  ASSERT_TRUE(cv::imwrite(path, depth));
  const cv::Mat read = ReadImageFile(path);
  ASSERT_EQ(read.type(), CV_32FC1);
  EXPECT_EQ(cv::norm(read, depth, cv::NORM_INF), 0);
  for (const std::string name : {"image_file_test.bmp", "image_file_test.jpg"}) {
    const std::string other = ::testing::TempDir() + "/" + name;
    ASSERT_TRUE(cv::imwrite(other, cv::Mat(5, 6, CV_8UC1, cv::Scalar(7))));
    ::testing::internal::CaptureStderr();
    try {
      ReadImageFile(other);
      ADD_FAILURE() << "read " << other;
    } catch (const InputError& e) {
      EXPECT_EQ(e.problem(),
                "is neither a PNG nor a TIFF file (images are read as PNG; float32 TIFF for the simulator's depth "
                "maps)");
    }
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  }
  const std::string jpeg_named_png = Write("\xff\xd8\xff\xe0 a JPEG's start", "image_file_test_jpeg.png");
  try {
    ReadImageFile(jpeg_named_png);
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "is not a PNG file, though named .png");
  }
}

// The header is checked before a pixel is allocated or decoded: a header
// declaring 16000 x 16000 px over image data of one row is refused by the
// check (ReadGreyImage's size, given the camera's), not found damaged by
// decoding it (which allocated 256 MB first); the TIFF's header is checked
// too, once read.
TEST(ReadImageFile, TheHeaderIsCheckedBeforeDecoding) {
  const std::string row(1 + 16000, '\0');
  const std::string path =
      Write(kPngSignature + Chunk("IHDR", Ihdr(16000, 16000)) + Chunk("IDAT", Deflate(row, 9)) + Chunk("IEND", ""),
            "image_file_test_declared.png");
  ImageHeader seen;
  try {
    ReadImageFile(path, [&seen](const ImageHeader& header) {
      seen = header;
      throw InputError("check", "refused");
    });
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "refused");
  }
  EXPECT_EQ(seen.width_px, 16000);
  EXPECT_EQ(seen.height_px, 16000);
  EXPECT_EQ(seen.channels, 1);
  EXPECT_EQ(seen.bit_depth, 8);
  EXPECT_EQ(seen.stored_bit_depth, 8);
  try {
    ReadGreyImage(path, cv::Size(752, 582));
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "is 16000x16000, the rig says 752x582");
  }
  const std::string tiff = ::testing::TempDir() + "/image_file_test_header.tiff";
  ASSERT_TRUE(cv::imwrite(tiff, cv::Mat(23, 42, CV_32FC1, cv::Scalar(1.0f))));
  ReadImageFile(tiff, [&seen](const ImageHeader& header) { seen = header; });
  EXPECT_EQ(seen.width_px, 42);
  EXPECT_EQ(seen.height_px, 23);
  EXPECT_EQ(seen.bit_depth, 32);
}

}  // namespace
}  // namespace stereorig
