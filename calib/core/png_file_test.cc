#include "calib/core/png_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

const std::string kSignature = std::string("\x89PNG\r\n\x1a\n", 8);
const std::string kEnd = std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12);

std::string Write(const std::string& name, const std::string& bytes) {
  const std::string path = ::testing::TempDir() + "/png_file_test_" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// The checks read only the signature and the last chunk, so any bytes
// between stand for the image's chunks.
TEST(PngFile, AWholePngPassesAndOneCutShortIsNamed) {
  const std::string body(1000, 'x');
  EXPECT_TRUE(CheckPngIsWhole(Write("whole.png", kSignature + body + kEnd)));
  const std::string cut = Write("cut.png", kSignature + body + kEnd.substr(0, 5));
  try {
    CheckPngIsWhole(cut);
    ADD_FAILURE() << "a PNG without its IEND chunk passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cut short"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CheckPngIsWhole(Write("head_only.png", kSignature)), InputError);
  // Bytes after IEND are ignored by libpng, so the file is whole.
  EXPECT_TRUE(CheckPngIsWhole(Write("trailing.png", kSignature + body + kEnd + "x")));
  // Cut inside an image chunk: no IEND anywhere.
  EXPECT_THROW(CheckPngIsWhole(Write("cut_in_data.png", kSignature + std::string(10000, 'x'))), InputError);
}

TEST(PngFile, OtherFilesAreLeftToTheDecoder) {
  EXPECT_FALSE(CheckPngIsWhole(Write("junk.png", "not a png")));
  EXPECT_FALSE(CheckPngIsWhole(Write("empty.png", "")));
  EXPECT_FALSE(CheckPngIsWhole(Write("tiff.tif", std::string("II*\0", 4) + std::string(100, 'x'))));
  EXPECT_THROW(CheckPngIsWhole(::testing::TempDir() + "/png_file_test_no_such_file.png"), InputError);
}

}  // namespace
}  // namespace stereorig
