#include "calib/core/png_file.h"

#include <gtest/gtest.h>
#include <zlib.h>

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

// An IHDR's 13 bytes: width, height, bit depth, colour type (0 grey),
// compression, filter and interlace method.
std::string Ihdr(uint32_t width_px, uint32_t height_px, int bit_depth = 8, int colour_type = 0, int interlace = 0) {
  return BigEndian32(width_px) + BigEndian32(height_px) + std::string{char(bit_depth), char(colour_type), 0, 0} +
         char(interlace);
}

// `raw` as a zlib stream at compression `level` (0: stored, byte for byte).
std::string Deflate(const std::string& raw, int level) {
  uLongf size = compressBound(uLong(raw.size()));
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                      uLong(raw.size()), level),
            Z_OK);
  out.resize(size);
  return out;
}

// A 42 x 23 px 8-bit grey image's rows: each a filter byte (0, none) and 42
// pixels, 23 x 43 = 989 bytes.
std::string Rows(int num_bytes = 989) {
  std::string rows(size_t(num_bytes), '\0');
  for (size_t i = 0; i < rows.size(); ++i)
    if (i % 43) rows[i] = char(i * 7);
  return rows;
}

// Signature, IHDR (42 x 23 px, 8-bit grey), an IDAT of 1000 bytes (the rows
// stored: zlib's 2-byte header, a 5-byte stored-block header, the 989 bytes,
// the Adler-32) and IEND: 1 057 bytes, the IDAT's data at bytes 41-1040, its
// CRC at 1041-1044, IEND at 1045.
const std::string kImageData = Deflate(Rows(), 0);
const std::string kWhole = kSignature + Chunk("IHDR", Ihdr(42, 23)) + Chunk("IDAT", kImageData) + Chunk("IEND", "");

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
  ASSERT_EQ(kImageData.size(), 1000u);
  ASSERT_EQ(kWhole.size(), 1057u);
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

// Image data damaged under valid CRCs (the CRCs redone after the damage, as
// a faulty tool rewriting a file would): refused before libpng prints its
// own line ("libpng error: IDAT: invalid block type", "... incorrect data
// check", "Not enough image data").
TEST(PngFile, ImageDataThatDoesNotInflateToTheImageIsNamed) {
  const std::string head = kSignature + Chunk("IHDR", Ihdr(42, 23)), iend = Chunk("IEND", "");
  auto with_data = [&](const std::string& name, const std::string& data) {
    return Write(name, head + Chunk("IDAT", data) + iend);
  };
  std::string block_type = kImageData;
  block_type[2] |= 0x06;  // the first block's BTYPE 11: reserved
  ExpectRefused(with_data("block_type.png", block_type),
                "a damaged PNG (its image data does not inflate: invalid block type)");
  std::string pixel = kImageData;
  pixel[500] ^= 0x01;  // a stored byte: inflates, but fails the Adler-32
  ExpectRefused(with_data("pixel.png", pixel), "a damaged PNG (its image data does not inflate: incorrect data check)");
  const std::string cut = "a damaged PNG (its image data is cut short: its deflate stream does not end)";
  ExpectRefused(with_data("cut.png", kImageData.substr(0, 500)), cut);
  ExpectRefused(with_data("cut_before_checksum.png", kImageData.substr(0, 998)), cut);
  ExpectRefused(with_data("empty.png", ""), cut);
  ExpectRefused(with_data("short.png", Deflate(Rows(988), 9)),
                "a damaged PNG (its image data inflates to 988 bytes; its IHDR's 42 x 23 px image needs 989)");
  ExpectRefused(Write("no_idat.png", head + iend), "a damaged PNG (it has no IDAT chunk: no image data)");
  ExpectRefused(
      Write("idat_after_text.png", head + Chunk("IDAT", kImageData) + Chunk("tEXt", "abc") + Chunk("IDAT", "") + iend),
      "a damaged PNG (its IDAT chunk at byte " + std::to_string(head.size() + 12 + 1000 + 15) +
          " comes after other chunks that followed the image data: IDAT chunks must be consecutive)");
  // Nor may a chunk come between the IDATs while the stream runs: that
  // chunk is named (libpng: "Not enough image data").
  ExpectRefused(Write("text_between.png", head + Chunk("IDAT", kImageData.substr(0, 500)) + Chunk("tEXt", "abc") +
                                              Chunk("IDAT", kImageData.substr(500)) + iend),
                "a damaged PNG (its tEXt chunk at byte " + std::to_string(head.size() + 12 + 500) +
                    " comes between IDAT chunks, inside the image data's deflate stream: IDAT chunks must be "
                    "consecutive)");
}

// What libpng 1.6 decodes whole, with a warning ("libpng warning: IDAT:
// Extra compressed data", "IDAT: Too much image data"), passes: bytes after
// the stream's end, in its IDAT or the next, and a stream that inflates to
// more than the image needs.
TEST(PngFile, ImageDataLibpngReadsWholeWithAWarningPasses) {
  const std::string head = kSignature + Chunk("IHDR", Ihdr(42, 23)), iend = Chunk("IEND", "");
  EXPECT_TRUE(CheckPngIsWhole(Write("past_end.png", head + Chunk("IDAT", kImageData + "x") + iend)));
  EXPECT_TRUE(
      CheckPngIsWhole(Write("past_end_in_next.png", head + Chunk("IDAT", kImageData) + Chunk("IDAT", "junk") + iend)));
  EXPECT_TRUE(CheckPngIsWhole(Write("long.png", head + Chunk("IDAT", Deflate(Rows(990), 9)) + iend)));
  EXPECT_TRUE(CheckPngIsWhole(Write("longer.png", head + Chunk("IDAT", Deflate(Rows(100000), 9)) + iend)));
  // More than the image, then damage: inflating stops past the image's end,
  // before the damage (libpng decodes the image whole too, warning "IDAT:
  // incorrect data check").
  std::string damaged_after = Deflate(Rows(989 + 40000), 0);  // stored blocks of up to 65535 bytes
  damaged_after[2 + 5 + 989 + 20000] ^= 0x01;                 // a byte of the extra data: fails the Adler-32
  uLongf size = 989 + 40000;
  std::string inflated(size, '\0');
  ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(inflated.data()), &size,
                       reinterpret_cast<const Bytef*>(damaged_after.data()), uLong(damaged_after.size())),
            Z_DATA_ERROR);
  EXPECT_TRUE(CheckPngIsWhole(Write("damaged_after.png", head + Chunk("IDAT", damaged_after) + iend)));
}

// A deflate bomb: a 1 x 1 px header over a stream of 64 MiB of zeros (some
// 64 KB deflated). Inflating stops one byte past the image's 2 bytes, where
// the whole stream was inflated before and refused; libpng decodes it with a
// warning (too much image data).
TEST(PngFile, AStreamFarLongerThanTheImageIsReadOnlyAsFarAsTheImage) {
  z_stream z{};
  ASSERT_EQ(deflateInit(&z, 9), Z_OK);
  const std::string zeros(1 << 20, '\0');
  std::string bomb(1 << 20, '\0');
  size_t used = 0;
  int rc = Z_OK;
  for (int mib = 0; mib < 64; ++mib) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(zeros.data()));
    z.avail_in = uInt(zeros.size());
    const int flush = mib == 63 ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = reinterpret_cast<Bytef*>(bomb.data() + used);
      z.avail_out = uInt(bomb.size() - used);
      rc = deflate(&z, flush);
      used = bomb.size() - z.avail_out;
    } while (z.avail_in > 0);
  }
  ASSERT_EQ(rc, Z_STREAM_END);
  ASSERT_EQ(z.total_in, 64u << 20);
  ASSERT_EQ(deflateEnd(&z), Z_OK);
  bomb.resize(used);
  ASSERT_LT(bomb.size(), 100000u);
  const std::string head = kSignature + Chunk("IHDR", Ihdr(1, 1));
  EXPECT_TRUE(CheckPngIsWhole(Write("bomb.png", head + Chunk("IDAT", bomb) + Chunk("IEND", ""))));
}

// Headers beyond what the decoder reads: past libpng's 10^6 px a side,
// refused (libpng: "Image width exceeds user limit in IHDR"); past OpenCV's
// 2^30 px, the image data is left to the decoder, which refuses the header
// alone (reconstruct/image_file_test.cc): not inflated, so a damaged stream
// passes here.
TEST(PngFile, AnImageLargerThanTheDecoderReadsIsNotInflated) {
  std::string damaged = kImageData;
  damaged[2] |= 0x06;  // the first block's BTYPE 11: reserved
  auto with_ihdr = [&](const std::string& name, const std::string& ihdr) {
    return Write(name, kSignature + Chunk("IHDR", ihdr) + Chunk("IDAT", damaged) + Chunk("IEND", ""));
  };
  ExpectRefused(with_ihdr("wide.png", Ihdr(1000001, 1)),
                "a PNG too large to read (its IHDR gives an image of 1000001 x 1 px; libpng reads up to 1000000 px a "
                "side)");
  ExpectRefused(with_ihdr("tall.png", Ihdr(1, 1000001)),
                "a PNG too large to read (its IHDR gives an image of 1 x 1000001 px; libpng reads up to 1000000 px a "
                "side)");
  EXPECT_TRUE(CheckPngIsWhole(with_ihdr("60000x60000.png", Ihdr(60000, 60000))));
  EXPECT_TRUE(CheckPngIsWhole(with_ihdr("2^15x2^15+1.png", Ihdr(1 << 15, (1 << 15) + 1))));  // 2^30 + 2^15 px
  ExpectRefused(with_ihdr("2^15x2^15.png", Ihdr(1 << 15, 1 << 15)),                          // 2^30 px: inflated
                "a damaged PNG (its image data does not inflate: invalid block type)");
  // The IDATs are still checked for being there.
  ExpectRefused(Write("60000x60000_no_idat.png", kSignature + Chunk("IHDR", Ihdr(60000, 60000)) + Chunk("IEND", "")),
                "a damaged PNG (it has no IDAT chunk: no image data)");
}

// The stream may be split anywhere across consecutive IDATs, empty ones
// included, with other chunks before them and after; compressed or stored.
TEST(PngFile, ImageDataSplitAcrossIdatChunksPasses) {
  const std::string head = kSignature + Chunk("IHDR", Ihdr(42, 23)) + Chunk("tEXt", "abc");
  const std::string compressed = Deflate(Rows(), 9);
  ASSERT_LT(compressed.size(), kImageData.size());
  for (const std::string& data : {kImageData, compressed}) {
    const size_t cuts[] = {0, 1, 2, data.size() / 2, data.size()};
    std::string chunks;
    for (int i = 0; i < 4; ++i) chunks += Chunk("IDAT", data.substr(cuts[i], cuts[i + 1] - cuts[i]));
    EXPECT_TRUE(CheckPngIsWhole(Write("split.png", head + Chunk("IDAT", "") + chunks + Chunk("IDAT", "") +
                                                       Chunk("tEXt", "def") + Chunk("IEND", ""))));
  }
}

// An IHDR libpng refuses ("Invalid color type", "Image width is zero") is
// named as such: the image data's size cannot be known.
TEST(PngFile, AnIhdrPngDoesNotDefineIsNamed) {
  auto with_ihdr = [&](const std::string& name, const std::string& ihdr) {
    return Write(name, kSignature + Chunk("IHDR", ihdr) + Chunk("IDAT", kImageData) + Chunk("IEND", ""));
  };
  ExpectRefused(with_ihdr("colour_5.png", Ihdr(42, 23, 8, 5)),
                "a damaged PNG (its IHDR gives colour type 5 at bit depth 8, which PNG does not define)");
  ExpectRefused(with_ihdr("rgb_4bit.png", Ihdr(42, 23, 4, 2)),
                "a damaged PNG (its IHDR gives colour type 2 at bit depth 4, which PNG does not define)");
  ExpectRefused(with_ihdr("width_0.png", Ihdr(0, 23)), "a damaged PNG (its IHDR gives an image of 0 x 23 px)");
  ExpectRefused(with_ihdr("height_2^31.png", Ihdr(42, 0x80000000u)),
                "a damaged PNG (its IHDR gives an image of 42 x 2147483648 px)");
  ExpectRefused(with_ihdr("interlace_2.png", Ihdr(42, 23, 8, 0, 2)),
                "a damaged PNG (its IHDR gives compression, filter or interlace method 0, 0, 2, which PNG does not "
                "define)");
  ExpectRefused(with_ihdr("ihdr_14.png", Ihdr(42, 23) + "x"), "a damaged PNG (its IHDR chunk holds 14 bytes, not 13)");
}

TEST(PngFile, OtherFilesAreLeftToTheDecoder) {
  EXPECT_FALSE(CheckPngIsWhole(Write("junk.png", "not a png")));
  EXPECT_FALSE(CheckPngIsWhole(Write("empty.png", "")));
  EXPECT_FALSE(CheckPngIsWhole(Write("tiff.tif", std::string("II*\0", 4) + std::string(100, 'x'))));
  EXPECT_THROW(CheckPngIsWhole(::testing::TempDir() + "/png_file_test_no_such_file.png"), InputError);
}

}  // namespace
}  // namespace stereorig
