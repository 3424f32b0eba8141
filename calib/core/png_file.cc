#include "calib/core/png_file.h"

#include <zlib.h>

#include <fstream>
#include <optional>

#include "calib/core/input_error.h"
#include "calib/core/png_image_data.h"

namespace stereorig {
namespace {

uint32_t BigEndian32(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | uint32_t(b[3]);
}

bool IsChunkType(std::string_view type) {
  for (const char c : type)
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'))) return false;
  return true;
}

}  // namespace

uint32_t PngCrc(std::string_view bytes) {
  // zlib's, ten times a byte-wise table's speed: every byte of every image
  // read goes through it.
  return uint32_t(crc32(0, reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size())));
}

bool CheckPngIsWhole(const std::string& path) {
  static constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path, "cannot be opened");
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  f.seekg(0);
  std::string head(kSignature.size(), '\0');
  if (!f.read(head.data(), std::streamsize(head.size())) || head != kSignature) return false;
  // Each chunk: length (4 bytes, big-endian, < 2^31), type (4 letters), its
  // data, and the CRC of type and data. The buffer holds type and data.
  std::string chunk;
  std::optional<PngImageData> image_data;
  for (std::streamoff at = std::streamoff(kSignature.size());;) {
    char length_bytes[4];
    if (size - at < 12 || !f.read(length_bytes, 4))
      throw InputError(path, "a PNG cut short (no IEND chunk at its end: still being written?)");
    const uint32_t length = BigEndian32(length_bytes);
    chunk.resize(4);
    f.read(chunk.data(), 4);
    const std::string where = "chunk at byte " + std::to_string(at);
    if (!IsChunkType(chunk) || length > 0x7FFFFFFFu)
      throw InputError(path, "a damaged PNG (its " + where + " has no valid type or length)");
    const std::string named = "its " + chunk + " " + where;
    if (at == std::streamoff(kSignature.size()) && chunk != "IHDR")
      throw InputError(path, "a damaged PNG (" + named + " should be IHDR)");
    if (std::streamoff(length) > size - at - 12)
      throw InputError(
          path, "a PNG cut short or damaged (" + named + " is longer than the rest of the file: still being written?)");
    chunk.resize(4 + size_t(length));
    char crc_bytes[4];
    if (!f.read(chunk.data() + 4, std::streamsize(length)) || !f.read(crc_bytes, 4))
      throw InputError(path, "cannot be read");
    if (PngCrc(chunk) != BigEndian32(crc_bytes))
      throw InputError(path, "a damaged PNG (" + named + " fails its CRC check)");
    // Then the image data, inflated as it streams past (png_image_data.h).
    const std::string_view data = std::string_view(chunk).substr(4);
    if (!image_data) {
      image_data.emplace(path, data);  // IHDR, the first chunk
    } else if (chunk.compare(0, 4, "IDAT") == 0) {
      image_data->Add(data, uint64_t(at));
    } else if (chunk.compare(0, 4, "IEND") == 0) {
      image_data->Finish();
    } else {
      image_data->Interrupt(std::string_view(chunk).substr(0, 4), uint64_t(at));
    }
    if (chunk.compare(0, 4, "IEND") == 0) return true;
    at += 12 + std::streamoff(length);
  }
}

}  // namespace stereorig
