#include "calib/core/png_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

const std::string kSignature = std::string("\x89PNG\r\n\x1a\n", 8);

std::string BigEndian32(uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

// A chunk as PNG lays it out: length, type, data, CRC of type and data.
std::string Chunk(const std::string& type, const std::string& data) {
  return BigEndian32(uint32_t(data.size())) + type + data + BigEndian32(PngCrc(type + data));
}

// Signature, IHDR (13 bytes: the checks do not read it), an IDAT of 1000
// bytes (standing for the image) and IEND: 1 057 bytes, the IDAT's data at
// bytes 41-1040, its CRC at 1041-1044, IEND at 1045.
const std::string kWhole =
    kSignature + Chunk("IHDR", std::string(13, '\1')) + Chunk("IDAT", std::string(1000, 'x')) + Chunk("IEND", "");

std::string Write(const std::string& name, const std::string& bytes) {
  const std::string path = ::testing::TempDir() + "/png_file_test_" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// CheckPngIsWhole(path) throws an InputError naming the file and saying
// `says`.
void ExpectRefused(const std::string& path, const std::string& says) {
  try {
    CheckPngIsWhole(path);
    ADD_FAILURE() << path << " passed";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": " + says);
  }
}

// Against the check value of CRC-32 and the one every PNG's IEND carries.
TEST(PngFile, CrcIsPngs) {
  EXPECT_EQ(PngCrc("123456789"), 0xCBF43926u);
  EXPECT_EQ(PngCrc("IEND"), 0xAE426082u);
  EXPECT_EQ(kWhole.substr(kWhole.size() - 12), std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12));
}

TEST(PngFile, AWholePngPassesAndOneCutShortIsNamed) {
  EXPECT_TRUE(CheckPngIsWhole(Write("whole.png", kWhole)));
  // Bytes after IEND are ignored by libpng, so the file is whole.
  EXPECT_TRUE(CheckPngIsWhole(Write("trailing.png", kWhole + std::string(5000, 'x'))));
  const std::string no_iend = "a PNG cut short (no IEND chunk at its end: still being written?)";
  ExpectRefused(Write("cut.png", kWhole.substr(0, kWhole.size() - 7)), no_iend);
  ExpectRefused(Write("head_only.png", kSignature), no_iend);
  ExpectRefused(Write("cut_between_chunks.png", kWhole.substr(0, kWhole.size() - 12)), no_iend);
  ExpectRefused(
      Write("cut_in_data.png", kWhole.substr(0, 500)),
      "a PNG cut short or damaged (its IDAT chunk at byte 33 is longer than the rest of the file: still being "
      "written?)");
}

// A byte flipped anywhere fails a chunk's CRC: refused before libpng prints
// its own line (for a flip in IDAT's data, "bad adaptive filter value").
TEST(PngFile, ADamagedPngIsNamedWithTheChunk) {
  for (const size_t at : {size_t(41), size_t(500), size_t(1040), size_t(1042)}) {
    std::string damaged = kWhole;
    damaged[at] ^= 0x10;
    ExpectRefused(Write("damaged.png", damaged), "a damaged PNG (its IDAT chunk at byte 33 fails its CRC check)");
  }
  std::string iend = kWhole;
  iend[kWhole.size() - 1] ^= 0x01;
  ExpectRefused(Write("damaged_iend.png", iend), "a damaged PNG (its IEND chunk at byte 1045 fails its CRC check)");
  // A length or type damaged: no chunk to name.
  std::string type = kWhole;
  type[37] = '\x7f';
  ExpectRefused(Write("damaged_type.png", type), "a damaged PNG (its chunk at byte 33 has no valid type or length)");
  std::string length = kWhole;
  length[33] = '\x80';
  ExpectRefused(Write("damaged_length.png", length),
                "a damaged PNG (its chunk at byte 33 has no valid type or length)");
  ExpectRefused(Write("no_ihdr.png", kSignature + Chunk("IDAT", "x") + Chunk("IEND", "")),
                "a damaged PNG (its IDAT chunk at byte 8 should be IHDR)");
}

TEST(PngFile, OtherFilesAreLeftToTheDecoder) {
  EXPECT_FALSE(CheckPngIsWhole(Write("junk.png", "not a png")));
  EXPECT_FALSE(CheckPngIsWhole(Write("empty.png", "")));
  EXPECT_FALSE(CheckPngIsWhole(Write("tiff.tif", std::string("II*\0", 4) + std::string(100, 'x'))));
  EXPECT_THROW(CheckPngIsWhole(::testing::TempDir() + "/png_file_test_no_such_file.png"), InputError);
}

}  // namespace
}  // namespace stereorig
