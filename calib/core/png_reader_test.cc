// PngReader on PNGs built here byte by byte (calib/core/png_testing.h),
// whole and damaged in each way a capture can be: every refusal is one
// InputError naming the file, and libpng prints nothing, refused or not.
// That it decodes as imread does: reconstruct/image_file_test.cc.
#include "calib/core/png_reader.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <string>
#include <vector>

#include "calib/core/input_error.h"
#include "calib/core/png_testing.h"

namespace stereorig {
namespace {

using testing::BigEndian32;
using testing::Chunk;
using testing::Deflate;
using testing::Ihdr;
using testing::kPngSignature;

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
const std::string kHead = kPngSignature + Chunk("IHDR", Ihdr(42, 23));
const std::string kIend = Chunk("IEND", "");
const std::string kWhole = kHead + Chunk("IDAT", kImageData) + kIend;

// `png` read whole as the file "x.png": its pixels, and nothing on stderr.
std::vector<uint8_t> Read(const std::string& png) {
  ::testing::internal::CaptureStderr();
  std::vector<uint8_t> pixels;
  try {
    std::optional<PngReader> reader = PngReader::FromBytes("x.png", png);
    if (!reader) {
      ADD_FAILURE() << "not taken for a PNG";
    } else {
      const size_t row_bytes = size_t(reader->width_px()) * reader->channels() * reader->bit_depth() / 8;
      pixels.resize(row_bytes * reader->height_px());
      reader->Read(pixels.data(), row_bytes);
    }
  } catch (const InputError& e) {
    ADD_FAILURE() << e.what();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  return pixels;
}

// `png`, read as the file "x.png", is refused in one InputError that names
// it and says `says`; nothing on stderr.
void ExpectRefused(const std::string& png, const std::string& says) {
  ::testing::internal::CaptureStderr();
  try {
    std::optional<PngReader> reader = PngReader::FromBytes("x.png", png);
    ASSERT_TRUE(reader) << "not taken for a PNG";
    std::vector<uint8_t> pixels(size_t(reader->width_px()) * reader->height_px() * reader->channels() *
                                reader->bit_depth() / 8);
    reader->Read(pixels.data(), size_t(reader->width_px()) * reader->channels() * reader->bit_depth() / 8);
    ADD_FAILURE() << "read, where " << says;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "x.png: " + says);
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(PngReader, AWholePngIsReadAndOneCutShortIsNamed) {
  ASSERT_EQ(kImageData.size(), 1000u);
  ASSERT_EQ(kWhole.size(), 1057u);
  std::string rows = Rows();
  for (size_t r = 0; r < 23; ++r) rows.erase(r * 42, 1);  // the filter bytes
  EXPECT_EQ(Read(kWhole), std::vector<uint8_t>(rows.begin(), rows.end()));
  // Bytes after IEND are not read.
  EXPECT_EQ(Read(kWhole + std::string(5000, 'x')).size(), 42u * 23u);
  const std::string no_iend = "a PNG cut short (no IEND chunk at its end: still being written?)";
  ExpectRefused(kWhole.substr(0, kWhole.size() - 7), no_iend);
  ExpectRefused(kPngSignature, no_iend);
  ExpectRefused(kWhole.substr(0, kWhole.size() - 12), no_iend);
  ExpectRefused(
      kWhole.substr(0, 500),
      "a PNG cut short or damaged (its IDAT chunk at byte 33 is longer than the rest of the file: still being "
      "written?)");
  ExpectRefused(
      kWhole.substr(0, 1043),  // in the CRC
      "a PNG cut short or damaged (its IDAT chunk at byte 33 is longer than the rest of the file: still being "
      "written?)");
}

// A byte flipped anywhere is refused, naming the chunk: libpng checks a
// chunk's CRC once it has read the chunk, so a flip in IDAT's data is
// found first by zlib, as the data inflates (or by the image data's
// Adler-32) and a flip in its CRC by the CRC; a CRC that fails at an
// ancillary chunk too, where libpng only warns and drops the chunk.
// Grey of 1, 2 or 4 bits decodes as 8-bit (bit_depth() 8, as imread gives
// it); stored_bit_depth() keeps the file's own depth, which the capture
// readers (reconstruct's and calibrate's) refuse below 8.
TEST(PngReader, KeepsTheFilesOwnBitDepthBesideTheDecodedOne) {
  for (const int bits : {1, 2, 4, 8}) {
    std::string raw;  // 8 x 2 px: per row a filter byte and 8 samples packed
    for (int row = 0; row < 2; ++row) raw += '\0' + std::string(size_t(bits), '\x5a');
    const std::string png = kPngSignature + Chunk("IHDR", Ihdr(8, 2, bits, 0)) + Chunk("IDAT", Deflate(raw, 9)) + kIend;
    std::optional<PngReader> reader = PngReader::FromBytes("x.png", png);
    ASSERT_TRUE(reader.has_value()) << bits;
    EXPECT_EQ(reader->bit_depth(), 8) << bits;
    EXPECT_EQ(reader->stored_bit_depth(), bits);
  }
}

TEST(PngReader, ADamagedPngIsNamedWithTheChunk) {
  const std::pair<size_t, std::string> flips[] = {
      {41, "its image data (IDAT chunk at byte 33): incorrect header check"},  // zlib's header
      {500, "its image data (IDAT chunk at byte 33): incorrect data check"},   // a stored pixel
      {1040, "its image data (IDAT chunk at byte 33): incorrect data check"},  // the Adler-32
      {1042, "its IDAT chunk at byte 33 fails its CRC check"}};
  for (const auto& [at, says] : flips) {
    std::string damaged = kWhole;
    damaged[at] ^= 0x10;
    ExpectRefused(damaged, "a damaged PNG (" + says + ")");
  }
  std::string iend = kWhole;
  iend[kWhole.size() - 1] ^= 0x01;
  ExpectRefused(iend, "a damaged PNG (its IEND chunk at byte 1045 fails its CRC check)");
  std::string text = Chunk("tEXt", std::string("Software\0x", 10));  // keyword, NUL, text
  text[12] ^= 0x01;
  ExpectRefused(kHead + text + Chunk("IDAT", kImageData) + kIend,
                "a damaged PNG (its tEXt chunk at byte 33 fails its CRC check)");
  ExpectRefused(kHead + Chunk("IDAT", kImageData) + text + kIend,
                "a damaged PNG (its tEXt chunk at byte 1045 fails its CRC check)");
  // A length or type damaged: no chunk to name.
  std::string type = kWhole;
  type[37] = '\x7f';
  ExpectRefused(type, "a damaged PNG (its chunk at byte 33 has no valid type or length: [7F]DAT: invalid chunk type)");
  std::string length = kWhole;
  length[33] = '\x80';
  ExpectRefused(length,
                "a damaged PNG (its chunk at byte 33 has no valid type or length: PNG unsigned integer out of range)");
  ExpectRefused(kPngSignature + Chunk("IDAT", "x") + kIend,
                "a damaged PNG (its image data (IDAT chunk at byte 8): Missing IHDR before IDAT)");
}

// Image data damaged under valid CRCs (the CRCs redone after the damage, as
// a faulty tool rewriting a file would): libpng's error, in our line.
TEST(PngReader, ImageDataDamagedUnderValidCrcsIsNamed) {
  auto with_data = [&](const std::string& data) { return kHead + Chunk("IDAT", data) + kIend; };
  std::string block_type = kImageData;
  block_type[2] |= 0x06;  // the first block's BTYPE 11: reserved
  ExpectRefused(with_data(block_type), "a damaged PNG (its image data (IDAT chunk at byte 33): invalid block type)");
  std::string header = kImageData;
  header[0] ^= 0x10;  // zlib's header check fails
  ExpectRefused(with_data(header), "a damaged PNG (its image data (IDAT chunk at byte 33): incorrect header check)");
  for (const size_t at : {size_t(500), size_t(999)}) {  // a stored pixel; the Adler-32's last byte
    std::string pixel = kImageData;
    pixel[at] ^= 0x01;
    ExpectRefused(with_data(pixel), "a damaged PNG (its image data (IDAT chunk at byte 33): incorrect data check)");
  }
  std::string filter = Rows();
  filter[43] = 7;  // the second row's filter type: PNG has 0 to 4
  ExpectRefused(with_data(Deflate(filter, 9)),
                "a damaged PNG (its image data (IDAT chunk at byte 33): bad adaptive filter value)");
  const std::string ends_early = "a damaged PNG (its image data ends before the image does: Not enough image data)";
  ExpectRefused(with_data(kImageData.substr(0, 500)), ends_early);
  ExpectRefused(with_data(kImageData.substr(0, 998)), ends_early);
  ExpectRefused(with_data(""), ends_early);
  ExpectRefused(with_data(Deflate(Rows(988), 9)), ends_early);  // one byte short
  // A chunk between IDATs while the stream runs: the image data ends there.
  ExpectRefused(kHead + Chunk("IDAT", kImageData.substr(0, 500)) + Chunk("tEXt", "abc") +
                    Chunk("IDAT", kImageData.substr(500)) + kIend,
                ends_early);
  ExpectRefused(kHead + kIend, "a damaged PNG (its IEND chunk at byte 33: out of place)");  // no IDAT
}

// libpng decodes the last row before it reads the rest of the deflate
// stream, and then only warns of damage there ("libpng warning: IDAT:
// incorrect data check"), imread returning the image: refused here. The
// predecessor stopped inflating past the image's end, and passed it.
TEST(PngReader, DamageInTheImageDataPastTheImageIsRefused) {
  // Stored, 12000 bytes past the image: within the 16 KiB read past it
  // (AStreamFarLongerThanTheImageIsRefused).
  std::string damaged_after = Deflate(Rows(989 + 12000), 0);
  damaged_after[2 + 5 + 989 + 6000] ^= 0x01;  // a byte of the extra data: fails the Adler-32
  ExpectRefused(kHead + Chunk("IDAT", damaged_after) + kIend,
                "a damaged PNG (its image data (IDAT chunk at byte 33): incorrect data check)");
  // The Adler-32 alone in the next IDAT, damaged: read once the image is.
  std::string compressed = Deflate(Rows(), 9);
  compressed.back() ^= 0x01;
  const size_t n = compressed.size();
  ExpectRefused(kHead + Chunk("IDAT", compressed.substr(0, n - 4)) + Chunk("IDAT", compressed.substr(n - 4)) + kIend,
                "a damaged PNG (its image data (IDAT chunk at byte " + std::to_string(kHead.size() + 12 + n - 4) +
                    "): incorrect data check)");
}

// What libpng reads whole with a warning that the image data holds more
// than the image ("libpng warning: IDAT: Extra compressed data", "IDAT:
// Too much image data", "IDAT: ..Too many IDATs found") is read, silently:
// bytes after the stream's end, in its IDAT or the next; a stream that
// inflates to more than the image; an IDAT after another chunk that
// followed the image data (which the predecessor refused).
TEST(PngReader, ImageDataHoldingMoreThanTheImageIsRead) {
  const std::vector<uint8_t> whole = Read(kWhole);
  EXPECT_EQ(Read(kHead + Chunk("IDAT", kImageData + "x") + kIend), whole);
  EXPECT_EQ(Read(kHead + Chunk("IDAT", kImageData) + Chunk("IDAT", "junk") + kIend), whole);
  EXPECT_EQ(Read(kHead + Chunk("IDAT", Deflate(Rows(990), 9)) + kIend), whole);
  EXPECT_EQ(Read(kHead + Chunk("IDAT", Deflate(Rows(100000), 9)) + kIend), whole);
  EXPECT_EQ(Read(kHead + Chunk("IDAT", kImageData) + Chunk("tEXt", "abc") + Chunk("IDAT", "") + kIend), whole);
  EXPECT_EQ(Read(kHead + Chunk("IDAT", kImageData) + Chunk("tEXt", "abc") + Chunk("IDAT", "xy") + kIend), whole);
  // A text chunk longer than the bomb limit (16 KiB) between the image and
  // a later empty IDAT: its bytes are not inflated, so they do not count.
  EXPECT_EQ(
      Read(kHead + Chunk("IDAT", kImageData) + Chunk("tEXt", std::string(20000, 'a')) + Chunk("IDAT", "") + kIend),
      whole);
}

// The stream may be split anywhere across consecutive IDATs, empty ones
// included, with other chunks before them and after; compressed or stored.
TEST(PngReader, ImageDataSplitAcrossIdatChunksIsRead) {
  const std::vector<uint8_t> whole = Read(kWhole);
  const std::string head = kHead + Chunk("tEXt", "abc");
  const std::string compressed = Deflate(Rows(), 9);
  ASSERT_LT(compressed.size(), kImageData.size());
  for (const std::string& data : {kImageData, compressed}) {
    const size_t cuts[] = {0, 1, 2, data.size() / 2, data.size()};
    std::string chunks;
    for (int i = 0; i < 4; ++i) chunks += Chunk("IDAT", data.substr(cuts[i], cuts[i + 1] - cuts[i]));
    EXPECT_EQ(Read(head + Chunk("IDAT", "") + chunks + Chunk("IDAT", "") + Chunk("tEXt", "def") + kIend), whole);
  }
}

// Chunks whose contents libpng would warn about but imread does not use
// (an iCCP profile cut short, a PLTE in a grey image, data in IEND) and an
// unknown ancillary chunk are read past; an unknown critical chunk, which
// a decoder must understand, is refused, as by imread.
TEST(PngReader, ChunksImreadDoesNotUseAreReadPast) {
  const std::vector<uint8_t> whole = Read(kWhole);
  const std::string idat = Chunk("IDAT", kImageData);
  EXPECT_EQ(Read(kHead + Chunk("iCCP", std::string("x\0\0junk", 7)) + idat + kIend), whole);
  EXPECT_EQ(Read(kHead + Chunk("gAMA", BigEndian32(100000)) + idat + kIend), whole);  // gamma 1: not applied
  EXPECT_EQ(Read(kHead + Chunk("PLTE", "abc") + idat + kIend), whole);
  EXPECT_EQ(Read(kHead + idat + Chunk("IEND", "x")), whole);
  EXPECT_EQ(Read(kHead + Chunk("abcd", "x") + idat + kIend), whole);
  ExpectRefused(kHead + Chunk("ABCD", "x") + idat + kIend,
                "a damaged PNG (its ABCD chunk at byte 33: unhandled critical chunk)");
}

// A deflate bomb: a 1 x 1 px header over a stream of 64 MiB of zeros (some
// 64 KB deflated). libpng would inflate it to its end, 1 KB at a time, to
// see that it ends: 165 ms here, 4.4 s for a capture-sized file (1 MB)
// after a 752 x 582 image, where it was read. Refused once the image data
// read past the image's last row passes 16 KiB, in a few ms.
TEST(PngReader, AStreamFarLongerThanTheImageIsRefused) {
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
  ASSERT_EQ(deflateEnd(&z), Z_OK);
  bomb.resize(used);
  ASSERT_LT(bomb.size(), 100000u);
  ExpectRefused(kPngSignature + Chunk("IHDR", Ihdr(1, 1)) + Chunk("IDAT", bomb) + kIend,
                "a PNG whose image data goes on for more than 16 KiB past its image's end (at byte " +
                    std::to_string(8192 + 41) +
                    "): a decompression bomb or a faulty encoder, refused rather than inflated");
  // How fast is the bench's business, not this test's: the refusal's
  // byte says it stopped 8 KiB (libpng's read ahead) into the stream, under
  // 25 MiB inflated of the 64 MiB (165 ms whole, ~60 ms refused here).
}

// Headers beyond this reader's limits are refused from the header alone,
// before any image data is read: past libpng's 10^6 px a side (where libpng
// would print "Image width exceeds user limit in IHDR"), past 2^28 px.
TEST(PngReader, AnImageTooLargeIsRefusedFromItsHeader) {
  auto open = [&](const std::string& ihdr) {
    return PngReader::FromBytes("x.png", kPngSignature + Chunk("IHDR", ihdr) + Chunk("IDAT", "") + kIend);
  };
  auto refused = [&](const std::string& ihdr, const std::string& size) {
    try {
      open(ihdr);
      ADD_FAILURE() << size << " opened";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), "x.png: a PNG too large to read (its IHDR gives an image of " + size +
                                           " px; this reader takes up to 1000000 px a side and 268435456 px in all)");
    }
  };
  refused(Ihdr(1000001, 1), "1000001 x 1");
  refused(Ihdr(1, 1000001), "1 x 1000001");
  refused(Ihdr(60000, 60000), "60000 x 60000");
  refused(Ihdr(1 << 14, (1 << 14) + 1), "16384 x 16385");  // 2^28 + 2^14 px
  const std::optional<PngReader> largest = open(Ihdr(1 << 14, 1 << 14, 16, 6));
  ASSERT_TRUE(largest);
  EXPECT_EQ(largest->width_px(), 1u << 14);
  EXPECT_EQ(largest->channels(), 4);
  EXPECT_EQ(largest->bit_depth(), 16);
  const std::optional<PngReader> long_row = open(Ihdr(1000000, 1));
  ASSERT_TRUE(long_row);
  EXPECT_EQ(long_row->width_px(), 1000000u);
}

// An IHDR libpng refuses is named with libpng's reasons.
TEST(PngReader, AnIhdrPngDoesNotDefineIsNamed) {
  auto with_ihdr = [&](const std::string& ihdr) {
    return kPngSignature + Chunk("IHDR", ihdr) + Chunk("IDAT", kImageData) + kIend;
  };
  const std::string at = "a damaged PNG (its IHDR chunk at byte 8: ";
  ExpectRefused(with_ihdr(Ihdr(42, 23, 8, 5)), at + "Invalid color type in IHDR; Invalid IHDR data)");
  ExpectRefused(with_ihdr(Ihdr(42, 23, 4, 2)),
                at + "Invalid color type/bit depth combination in IHDR; Invalid IHDR data)");
  ExpectRefused(with_ihdr(Ihdr(0, 23)), at + "Image width is zero in IHDR; Invalid IHDR data)");
  ExpectRefused(with_ihdr(Ihdr(42, 0x80000000u)), at + "PNG unsigned integer out of range)");
  ExpectRefused(with_ihdr(Ihdr(42, 23, 8, 0, 2)), at + "Unknown interlace method in IHDR; Invalid IHDR data)");
  ExpectRefused(with_ihdr(Ihdr(42, 23) + "x"), at + "invalid)");
}

// The layout imread gives, from the header: grey of any depth up to 8 bits
// as 8; a tRNS chunk makes colour and palette images 4-channel.
TEST(PngReader, TheLayoutIsImreadsFromTheHeader) {
  struct Case {
    std::string ihdr, before_idat;
    int channels, bit_depth;
  };
  const std::string plte = Chunk("PLTE", std::string(6, 'x'));
  const Case cases[] = {{Ihdr(3, 2, 1, 0), "", 1, 8},
                        {Ihdr(3, 2, 16, 0), "", 1, 16},
                        {Ihdr(3, 2, 8, 0), Chunk("tRNS", std::string(2, '\0')), 1, 8},
                        {Ihdr(3, 2, 8, 4), "", 4, 8},
                        {Ihdr(3, 2, 8, 2), "", 3, 8},
                        {Ihdr(3, 2, 16, 2), Chunk("tRNS", std::string(6, '\0')), 4, 16},
                        {Ihdr(3, 2, 4, 3), plte, 3, 8},
                        {Ihdr(3, 2, 4, 3), plte + Chunk("tRNS", "\x80"), 4, 8},
                        {Ihdr(3, 2, 16, 6), "", 4, 16}};
  for (const Case& c : cases) {
    const std::optional<PngReader> png = PngReader::FromBytes(
        "x.png", kPngSignature + Chunk("IHDR", c.ihdr) + c.before_idat + Chunk("IDAT", "") + kIend);
    ASSERT_TRUE(png);
    EXPECT_EQ(png->width_px(), 3u);
    EXPECT_EQ(png->height_px(), 2u);
    EXPECT_EQ(png->channels(), c.channels) << int(c.ihdr[8]) << " bits, colour type " << int(c.ihdr[9]);
    EXPECT_EQ(png->bit_depth(), c.bit_depth) << int(c.ihdr[8]) << " bits, colour type " << int(c.ihdr[9]);
  }
}

// A file a camera has only just created is named as that, not as another
// format ("is not a PNG file, though named .png", its callers said).
TEST(PngReader, AnEmptyFileIsNamedEmpty) {
  const std::string path = ::testing::TempDir() + "/png_reader_test_empty.png";
  std::ofstream(path, std::ios::binary | std::ios::trunc).close();
  for (const bool from_file : {true, false}) {
    try {
      from_file ? PngReader::Open(path) : PngReader::FromBytes(path, "");
      ADD_FAILURE() << "read";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": is empty (0 bytes: still being written?)");
    }
  }
}

TEST(PngReader, OtherFilesAreNotPngs) {
  EXPECT_FALSE(PngReader::FromBytes("junk.png", "not a png"));
  EXPECT_FALSE(PngReader::FromBytes("short.png", kPngSignature.substr(0, 7)));
  EXPECT_FALSE(PngReader::FromBytes("x.tif", std::string("II*\0", 4) + std::string(100, 'x')));
  const std::string path = ::testing::TempDir() + "/png_reader_test.png";
  std::ofstream(path, std::ios::binary) << kWhole;
  const std::optional<PngReader> from_file = PngReader::Open(path);
  ASSERT_TRUE(from_file);
  EXPECT_EQ(from_file->width_px(), 42u);
  try {
    PngReader::Open(::testing::TempDir() + "/png_reader_test_no_such_file.png");
    ADD_FAILURE() << "opened";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "cannot be opened");
  }
}

}  // namespace
}  // namespace stereorig
