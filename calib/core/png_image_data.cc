#include "calib/core/png_image_data.h"

#include <zlib.h>

#include <algorithm>
#include <new>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

uint32_t BigEndian32(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | uint32_t(b[3]);
}

// a + b and a * b, saturated at UINT64_MAX (PngImageDataBytes).
uint64_t SaturatedAdd(uint64_t a, uint64_t b) {
  uint64_t sum;
  return __builtin_add_overflow(a, b, &sum) ? UINT64_MAX : sum;
}
uint64_t SaturatedMultiply(uint64_t a, uint64_t b) {
  uint64_t product;
  return __builtin_mul_overflow(a, b, &product) ? UINT64_MAX : product;
}

uint64_t RowsBytes(uint64_t width_px, uint64_t height_px, int bit_depth, int channels) {
  if (width_px == 0 || height_px == 0) return 0;  // an empty pass: no row, no filter byte
  // Below 2^31 px x 64 bits a pixel: below 2^37, no overflow.
  const uint64_t row_bytes = (width_px * uint64_t(bit_depth) * uint64_t(channels) + 7) / 8;
  return SaturatedMultiply(height_px, 1 + row_bytes);
}

// The channels of a colour type at a bit depth PNG allows for it (PNG
// specification, 11.2.2), or 0.
int Channels(int colour_type, int bit_depth) {
  const bool up_to_8 = bit_depth == 1 || bit_depth == 2 || bit_depth == 4 || bit_depth == 8;
  const bool eight_or_16 = bit_depth == 8 || bit_depth == 16;
  switch (colour_type) {
    case 0:
      return up_to_8 || bit_depth == 16 ? 1 : 0;  // grey
    case 2:
      return eight_or_16 ? 3 : 0;  // RGB
    case 3:
      return up_to_8 ? 1 : 0;  // palette index
    case 4:
      return eight_or_16 ? 2 : 0;  // grey + alpha
    case 6:
      return eight_or_16 ? 4 : 0;  // RGBA
    default:
      return 0;
  }
}

}  // namespace

uint64_t PngImageDataBytes(uint32_t width_px, uint32_t height_px, int bit_depth, int channels, bool interlaced) {
  if (!interlaced) return RowsBytes(width_px, height_px, bit_depth, channels);
  // Adam7: pass p takes the pixels at x0 + k dx, y0 + k dy (PNG
  // specification, 8.2).
  static constexpr int kX0[7] = {0, 4, 0, 2, 0, 1, 0}, kDx[7] = {8, 8, 4, 4, 2, 2, 1};
  static constexpr int kY0[7] = {0, 0, 4, 0, 2, 0, 1}, kDy[7] = {8, 8, 8, 4, 4, 2, 2};
  uint64_t bytes = 0;
  for (int p = 0; p < 7; ++p) {
    const uint64_t w = width_px > uint32_t(kX0[p]) ? (uint64_t(width_px) - kX0[p] + kDx[p] - 1) / kDx[p] : 0;
    const uint64_t h = height_px > uint32_t(kY0[p]) ? (uint64_t(height_px) - kY0[p] + kDy[p] - 1) / kDy[p] : 0;
    bytes = SaturatedAdd(bytes, RowsBytes(w, h, bit_depth, channels));
  }
  return bytes;
}

PngImageData::PngImageData(const std::string& path, std::string_view ihdr) : path_(path) {
  if (ihdr.size() != 13) Fail("its IHDR chunk holds " + std::to_string(ihdr.size()) + " bytes, not 13");
  width_px_ = BigEndian32(ihdr.data());
  height_px_ = BigEndian32(ihdr.data() + 4);
  const int bit_depth = static_cast<unsigned char>(ihdr[8]), colour_type = static_cast<unsigned char>(ihdr[9]);
  const int compression = static_cast<unsigned char>(ihdr[10]), filter = static_cast<unsigned char>(ihdr[11]);
  const int interlace = static_cast<unsigned char>(ihdr[12]);
  const std::string size = std::to_string(width_px_) + " x " + std::to_string(height_px_) + " px";
  if (width_px_ == 0 || height_px_ == 0 || width_px_ > 0x7FFFFFFFu || height_px_ > 0x7FFFFFFFu)
    Fail("its IHDR gives an image of " + size);
  if (width_px_ > kMaxSidePx || height_px_ > kMaxSidePx)
    throw InputError(path_, "a PNG too large to read (its IHDR gives an image of " + size + "; libpng reads up to " +
                                std::to_string(kMaxSidePx) + " px a side)");
  const int channels = Channels(colour_type, bit_depth);
  if (channels == 0)
    Fail("its IHDR gives colour type " + std::to_string(colour_type) + " at bit depth " + std::to_string(bit_depth) +
         ", which PNG does not define");
  if (compression != 0 || filter != 0 || interlace > 1)
    Fail("its IHDR gives compression, filter or interlace method " + std::to_string(compression) + ", " +
         std::to_string(filter) + ", " + std::to_string(interlace) + ", which PNG does not define");
  expected_bytes_ = PngImageDataBytes(width_px_, height_px_, bit_depth, channels, interlace == 1);
  if (uint64_t(width_px_) * height_px_ > kMaxPixels) return;  // the decoder refuses it from the header
  stream_ = std::make_unique<z_stream>();
  if (inflateInit(stream_.get()) != Z_OK) throw std::bad_alloc();
  // 32 KB, zlib's window; 1 MB measured no faster on the demo's captures.
  scratch_.resize(32 * 1024);
}

PngImageData::~PngImageData() {
  if (stream_) inflateEnd(stream_.get());
}

void PngImageData::Fail(const std::string& problem) const {
  throw InputError(path_, "a damaged PNG (" + problem + ")");
}

void PngImageData::Add(std::string_view idat_data, uint64_t at) {
  if (!interrupted_by_.empty()) {
    if (!ended_)
      Fail(interrupted_by_ + " comes between IDAT chunks, inside the image data's deflate stream: IDAT chunks " +
           "must be consecutive");
    Fail("its IDAT chunk at byte " + std::to_string(at) +
         " comes after other chunks that followed the image data: IDAT chunks must be consecutive");
  }
  started_ = true;
  // Bytes after the stream's end or past the image's: libpng ignores them.
  if (!stream_ || ended_ || idat_data.empty()) return;
  // zlib's avail_in is 32 bits, a chunk's length below 2^31: one go.
  stream_->next_in = reinterpret_cast<Bytef*>(const_cast<char*>(idat_data.data()));
  stream_->avail_in = uInt(idat_data.size());
  while (stream_->avail_in > 0) {
    // Up to one byte past the image: that byte shows the stream gives more.
    const uint64_t wanted = expected_bytes_ + 1 - inflated_bytes_;
    const uInt room = uInt(std::min<uint64_t>(scratch_.size(), wanted));
    stream_->next_out = scratch_.data();
    stream_->avail_out = room;
    const int rc = inflate(stream_.get(), Z_NO_FLUSH);
    inflated_bytes_ += room - stream_->avail_out;
    if (rc == Z_STREAM_END || inflated_bytes_ > expected_bytes_) {
      ended_ = true;
      return;
    }
    if (rc == Z_MEM_ERROR) throw std::bad_alloc();
    if (rc == Z_NEED_DICT) Fail("its image data does not inflate: its deflate stream asks for a preset dictionary");
    if (rc != Z_OK && rc != Z_BUF_ERROR)  // Z_DATA_ERROR: damage, zlib's message says which
      Fail(std::string("its image data does not inflate: ") + (stream_->msg ? stream_->msg : zError(rc)));
  }
}

void PngImageData::Interrupt(std::string_view chunk_type, uint64_t at) {
  if (started_ && interrupted_by_.empty())
    interrupted_by_ = "its " + std::string(chunk_type) + " chunk at byte " + std::to_string(at);
}

void PngImageData::Finish() {
  if (finished_) return;
  finished_ = true;
  if (!started_) Fail("it has no IDAT chunk: no image data");
  if (!stream_) return;  // over kMaxPixels: the decoder's
  if (!ended_) Fail("its image data is cut short: its deflate stream does not end");
  if (inflated_bytes_ < expected_bytes_)
    Fail("its image data inflates to " + std::to_string(inflated_bytes_) + " bytes; its IHDR's " +
         std::to_string(width_px_) + " x " + std::to_string(height_px_) + " px image needs " +
         std::to_string(expected_bytes_));
}

}  // namespace stereorig
