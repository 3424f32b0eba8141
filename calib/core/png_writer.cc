#include "calib/core/png_writer.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <new>
#include <stdexcept>
#include <vector>

#include "calib/core/png_reader.h"

namespace stereorig {

namespace {

// What libpng writes into and the error it stopped on. libpng's errors
// reach OnError, which keeps the message and longjmps back to
// GuardedEncode; its warnings (none for a layout checked beforehand) are
// dropped, never printed.
struct PngEncoding {
  std::string bytes;
  char error[256] = {};  // libpng's message, copied: it may live in a frame the longjmp leaves
  bool out_of_memory = false;
};

PngEncoding& EncodingOf(png_structp png) { return *static_cast<PngEncoding*>(png_get_io_ptr(png)); }

void WriteToBytes(png_structp png, png_bytep data, size_t length) {
  PngEncoding& e = EncodingOf(png);
  try {
    e.bytes.append(reinterpret_cast<const char*>(data), length);
  } catch (...) {  // must not unwind through libpng's C frames
    e.out_of_memory = true;
  }
  // Outside the handler: a longjmp out of a catch block would leave the
  // exception unfinished.
  if (e.out_of_memory) png_error(png, "out of memory");
}

void FlushNothing(png_structp) {}

[[noreturn]] void OnError(png_structp png, png_const_charp message) {
  PngEncoding& e = *static_cast<PngEncoding*>(png_get_error_ptr(png));
  std::snprintf(e.error, sizeof e.error, "%s", message);
  png_longjmp(png, 1);
}

void OnWarning(png_structp, png_const_charp) {}

// libpng under a setjmp: its errors longjmp back here (OnError) and it
// returns false. So no object with a destructor may live in this frame.
bool GuardedEncode(png_structp png, png_infop info, const PngImage& image, int compression_level, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, png_get_error_ptr(png), WriteToBytes, FlushNothing);
  png_set_compression_level(png, compression_level);
  const int colour_type = image.channels == 1   ? PNG_COLOR_TYPE_GRAY
                          : image.channels == 3 ? PNG_COLOR_TYPE_RGB
                                                : PNG_COLOR_TYPE_RGB_ALPHA;
  png_set_IHDR(png, info, image.width_px, image.height_px, image.bit_depth, colour_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (image.channels > 1) png_set_bgr(png);  // stored R, G, B(, A): given B, G, R(, A)
  if (image.bit_depth == 16 && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) png_set_swap(png);  // PNG's are big-endian
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

}  // namespace

std::string EncodePng(const PngImage& image, int compression_level) {
  if (image.channels != 1 && image.channels != 3 && image.channels != 4)
    throw std::invalid_argument("EncodePng: channels must be 1, 3 or 4");
  if (image.bit_depth != 8 && image.bit_depth != 16)
    throw std::invalid_argument("EncodePng: bit depth must be 8 or 16");
  // libpng's limit on a side when writing too (its user limits' default).
  if (image.width_px == 0 || image.height_px == 0 || image.width_px > PngReader::kMaxSidePx ||
      image.height_px > PngReader::kMaxSidePx)
    throw std::invalid_argument("EncodePng: a side must be in [1, 1000000] px");
  if (compression_level < 0 || compression_level > 9)
    throw std::invalid_argument("EncodePng: compression level must be in [0, 9]");
  if (image.row_stride_bytes < size_t(image.width_px) * size_t(image.channels) * size_t(image.bit_depth / 8))
    throw std::invalid_argument("EncodePng: a row stride shorter than a row");

  PngEncoding e;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &e, OnError, OnWarning);
  if (png == nullptr) throw std::bad_alloc();
  png_infop info = png_create_info_struct(png);
  std::vector<png_bytep> rows;
  try {
    if (info == nullptr) throw std::bad_alloc();
    rows.resize(image.height_px);
    for (size_t y = 0; y < rows.size(); ++y)
      rows[y] = const_cast<png_bytep>(static_cast<const png_byte*>(image.pixels) + y * image.row_stride_bytes);
  } catch (...) {
    png_destroy_write_struct(&png, &info);
    throw;
  }
  const bool encoded = GuardedEncode(png, info, image, compression_level, rows.data());
  png_destroy_write_struct(&png, &info);
  if (e.out_of_memory) throw std::bad_alloc();
  if (!encoded) throw std::runtime_error(std::string("EncodePng: libpng: ") + e.error);
  return std::move(e.bytes);
}

}  // namespace stereorig
