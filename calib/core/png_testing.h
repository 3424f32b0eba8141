// Test helpers that build PNG files byte by byte, whole or damaged, with
// zlib: chunks with their CRCs, headers, deflate streams.
#pragma once

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <string>

namespace stereorig::testing {

inline const std::string kPngSignature("\x89PNG\r\n\x1a\n", 8);

inline std::string BigEndian32(uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

// The CRC-32 a PNG chunk stores over its type and data.
inline uint32_t PngCrc(const std::string& bytes) {
  return uint32_t(crc32(0, reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size())));
}

// A chunk as PNG lays it out: length, type, data, CRC of type and data.
inline std::string Chunk(const std::string& type, const std::string& data) {
  return BigEndian32(uint32_t(data.size())) + type + data + BigEndian32(PngCrc(type + data));
}

// An IHDR's 13 bytes: width, height, bit depth, colour type (0 grey),
// compression, filter and interlace method.
inline std::string Ihdr(uint32_t width_px, uint32_t height_px, int bit_depth = 8, int colour_type = 0,
                        int interlace = 0) {
  return BigEndian32(width_px) + BigEndian32(height_px) + std::string{char(bit_depth), char(colour_type), 0, 0} +
         char(interlace);
}

// `raw` as a zlib stream at compression `level` (0: stored, byte for byte).
inline std::string Deflate(const std::string& raw, int level) {
  uLongf size = compressBound(uLong(raw.size()));
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                      uLong(raw.size()), level),
            Z_OK);
  out.resize(size);
  return out;
}

// The chunk at byte `at` of `png` with its CRC redone, as a faulty tool
// rewriting a file would after damaging its data.
inline void RedoCrc(std::string& png, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(png.data() + at);
  const size_t length = size_t(b[0]) << 24 | size_t(b[1]) << 16 | size_t(b[2]) << 8 | b[3];
  png.replace(at + 8 + length, 4, BigEndian32(PngCrc(png.substr(at + 4, 4 + length))));
}

}  // namespace stereorig::testing
