#include "calib/core/png_reader.h"

#include <png.h>

#include <csetjmp>
#include <cstring>
#include <fstream>
#include <new>
#include <string_view>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

// What libpng reads from (the whole file, in memory) and what it said.
// libpng's errors reach OnError, which keeps the message and longjmps back
// to the Guarded* function that called libpng; its warnings reach
// OnWarning. Neither prints.
struct PngDecoding {
  std::string path, bytes;
  size_t at = 0;        // the next byte libpng reads
  size_t chunk_at = 0;  // where the chunk libpng is reading starts: its length field
  // The file ended where libpng wanted more; `between_chunks` if that was a
  // chunk's 8-byte header (the last chunk read was not IEND).
  bool cut_short = false, between_chunks = false;
  // libpng's error, and the first of its warnings taken as damage
  // (OnWarning), each with the chunk it came at.
  // `in_header`: while libpng checked a chunk's length and type, its type
  // then not known (a damaged one, or still the chunk before's).
  struct Said {
    std::string message, chunk_type;  // chunk_type: "IDAT"
    size_t chunk_at = 0;
    bool in_header = false;
  } error, refusal;
  // The warnings at the chunk being read, "; "-joined: the reasons libpng
  // gives before its error about an IHDR ("Image width is zero in IHDR",
  // then "Invalid IHDR data").
  std::string warnings;
  size_t warnings_at = 0;
  bool refused = false, read = false;
  // Set once the image's last row is decoded, at byte `image_end_at`: image
  // data read past it (IDAT bytes only, `idat_bytes_after_image`: not the
  // chunks between, which are not inflated) beyond kMaxBytesAfterImage sets
  // `too_much_data`.
  bool image_done = false, too_much_data = false;
  size_t image_end_at = 0, idat_bytes_after_image = 0;
  png_structp png = nullptr;
  png_infop info = nullptr;

  ~PngDecoding() { png_destroy_read_struct(&png, &info, nullptr); }
};

namespace {

constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);
constexpr png_uint_32 kIdat = 0x49444154;  // "IDAT", as png_get_io_chunk_type gives it

PngDecoding& DecodingOf(png_structp png) { return *static_cast<PngDecoding*>(png_get_error_ptr(png)); }

// The type of the chunk libpng is reading: "IDAT".
std::string ChunkType(png_structp png) {
  const png_uint_32 type = png_get_io_chunk_type(png);
  return {char(type >> 24), char(type >> 16), char(type >> 8), char(type)};
}

// libpng's message without the "IDAT: " its chunk errors and warnings start
// with (png_chunk_error, png_chunk_warning).
std::string_view WithoutChunkName(std::string_view message) {
  return message.size() > 6 && message.substr(4, 2) == ": " ? message.substr(6) : message;
}

// Keeps what libpng said, in a callback libpng calls: bad_alloc must not
// unwind through libpng's C frames (the message is then lost, not the
// refusal: the caller tests the flags).
void Keep(PngDecoding::Said& said, png_structp png, const PngDecoding& d, std::string_view message) noexcept {
  try {
    said.message = message;
    said.chunk_type = ChunkType(png);
    said.chunk_at = d.chunk_at;
    said.in_header = (png_get_io_state(png) & PNG_IO_MASK_LOC) == PNG_IO_CHUNK_HDR;
  } catch (const std::bad_alloc&) {
  }
}

// Image data read after the image's last row is decoded: libpng inflates
// it to the stream's end ("Too much image data", below) at ~2.5 ms a MiB
// inflated, and deflate packs up to ~1032 bytes into one. A capture-sized
// file (1 MB) of zeros after a 752 x 582 image took 4.4 s, a cycle's time
// twenty times over: more than this is refused instead. A whole image's
// stream has a few bytes left at its last row (its end code, Adler-32);
// libpng has read ahead at most 8 KiB (PNG_IDAT_READ_SIZE) by then.
constexpr size_t kMaxBytesAfterImage = 16 * 1024;

void ReadFromBytes(png_structp png, png_bytep out, size_t length) {
  PngDecoding& d = DecodingOf(png);
  const bool chunk_header = (png_get_io_state(png) & PNG_IO_MASK_LOC) == PNG_IO_CHUNK_HDR;
  if (chunk_header) d.chunk_at = d.at;
  if (d.read && !chunk_header && png_get_io_chunk_type(png) == kIdat) {
    // Every row decoded: libpng is inflating the stream's rest, from within
    // its last row's read (png_read_finish_IDAT), so this is the one place
    // that sees it. Interlaced, the passes end at 7.
    const bool rows_done = png_get_interlace_type(png, d.info) == PNG_INTERLACE_NONE
                               ? png_get_current_row_number(png) >= png_get_image_height(png, d.info)
                               : png_get_current_pass_number(png) >= 7;
    if (rows_done && !d.image_done) {
      d.image_done = true;
      d.image_end_at = d.at;
    }
    if (d.image_done) d.idat_bytes_after_image += length;
    if (d.idat_bytes_after_image > kMaxBytesAfterImage) {
      d.too_much_data = true;
      png_error(png, "too much image data");
    }
  }
  if (length > d.bytes.size() - d.at) {
    d.cut_short = true;
    d.between_chunks = chunk_header;
    png_error(png, "cut short");
  }
  std::memcpy(out, d.bytes.data() + d.at, length);
  d.at += length;
}

[[noreturn]] void OnError(png_structp png, png_const_charp message) {
  PngDecoding& d = DecodingOf(png);
  Keep(d.error, png, d, message);
  png_longjmp(png, 1);
}

// Which of libpng's warnings are damage. Only those at the image data: how
// libpng 1.6 reports damage it finds once the image's last row is decoded,
// while it reads the rest of the deflate stream to its end, is a warning
// ("benign error") carrying zlib's message, after which imread returns the
// image, damaged pixels included: "IDAT: incorrect data check" (the
// stream's Adler-32 fails: under CRCs that pass, bytes of the image data
// changed, a faulty tool having rewritten the file), or "invalid distance
// too far back", "invalid block type", ... for damage past the image's end.
// Refused. (Damage before the last row is an error: "IDAT: invalid block
// type", "bad adaptive filter value"; a stream ending before the image,
// "Not enough image data".) One gap is libpng's: where the stream's last
// bytes, after the image's, are split across two or more IDATs still to
// read, it stops at the first without a warning, the Adler-32 unchecked
// (every chunk's CRC still is).
//
// Four warnings at the image data pass. Three say it holds more than the
// image, which libpng reads whole, ignoring the rest, as imread always has:
// - "Extra compressed data": bytes after the deflate stream's end;
// - "Too much image data": a stream that inflates to more than the image
//   (inflated to its end, 1 KB at a time; 165 ms for 64 MiB of zeros in a
//   64 KB file), up to kMaxBytesAfterImage of image data past the image's
//   last row: ReadFromBytes stops a deflate bomb there;
// - "..Too many IDATs found": an IDAT after the stream's end, or after a
//   chunk that followed the IDATs (refused by this reader's predecessor,
//   though the image is whole).
// The fourth, "Read palette index exceeding num_palette", is an encoder's
// fault, not damage (the checksums passed): those pixels decode to black,
// as in imread.
// Warnings at other chunks pass too: libpng reads IHDR (whose warnings end
// in its error, "Invalid IHDR data"), PLTE, tRNS and IEND only, skipping
// every other chunk after checking its CRC (png_set_keep_unknown_chunks),
// and a CRC that fails is an error (png_set_crc_action), at any chunk.
bool IsDamage(png_structp png, std::string_view message) {
  if (png_get_io_chunk_type(png) != kIdat) return false;
  std::string_view m = WithoutChunkName(message);
  while (!m.empty() && m.front() == '.') m.remove_prefix(1);
  return m != "Extra compressed data" && m != "Too much image data" && m != "Too many IDATs found" &&
         m != "Read palette index exceeding num_palette";
}

void OnWarning(png_structp png, png_const_charp message) {
  PngDecoding& d = DecodingOf(png);
  if (IsDamage(png, message) && !d.refused) {
    d.refused = true;
    Keep(d.refusal, png, d, message);
  }
  try {
    if (d.warnings_at != d.chunk_at) d.warnings.clear();
    d.warnings_at = d.chunk_at;
    d.warnings += (d.warnings.empty() ? "" : "; ") + std::string(message);
  } catch (const std::bad_alloc&) {
  }
}

// Each Guarded* function calls libpng under a setjmp: libpng's errors
// longjmp back to it (OnError) and it returns false. So no object with a
// destructor may live in these frames: a longjmp would skip it.

bool GuardedReadHeader(png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_sig_bytes(png, int(kSignature.size()));  // read by FromBytes
  // A CRC that fails is an error at every chunk; by default it is one only
  // at critical chunks, an ancillary chunk's being dropped with a warning.
  png_set_crc_action(png, PNG_CRC_ERROR_QUIT, PNG_CRC_ERROR_QUIT);
  // Skip every ancillary chunk but tRNS (which gives imread's 4th channel),
  // CRC checked: imread decodes no other (no gamma or colour conversion),
  // and their checks only warn ("iCCP: known incorrect sRGB profile").
  png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, nullptr, -1);
  // PNG's own limit: this reader's are checked with its own message
  // (PngReader::FromBytes), where libpng's would be "Invalid IHDR data".
  png_set_user_limits(png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  png_read_info(png, info);
  return true;
}

// The transforms OpenCV 4.6's PngDecoder::readData sets for
// IMREAD_UNCHANGED, in its order, `channels` its Mat's: imread's pixels,
// byte for byte. Sets `row_bytes` to libpng's decoded row.
bool GuardedSetUpTransforms(png_structp png, png_infop info, int channels, size_t* row_bytes) {
  if (setjmp(png_jmpbuf(png))) return false;
  const int colour_type = png_get_color_type(png, info), bit_depth = png_get_bit_depth(png, info);
  if (bit_depth == 16 && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) png_set_swap(png);  // PNG's are big-endian
  if (channels < 4) {
    png_set_strip_alpha(png);
  } else {
    png_set_tRNS_to_alpha(png);
  }
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((colour_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if ((colour_type & PNG_COLOR_MASK_COLOR) != 0 && channels > 1) {
    png_set_bgr(png);
  } else if (channels > 1) {
    png_set_gray_to_rgb(png);
  } else {
    png_set_rgb_to_gray(png, PNG_ERROR_ACTION_NONE, 0.299, 0.587);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  *row_bytes = png_get_rowbytes(png, info);
  return true;
}

bool GuardedReadImage(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  // To IEND: the rest of the deflate stream (its Adler-32) and every chunk's
  // CRC, so that a file cut short or damaged after the image is refused too.
  png_read_end(png, info);
  return true;
}

// The one line for what went wrong, libpng having stopped or warned.
[[noreturn]] void Refuse(const PngDecoding& d) {
  if (d.too_much_data)
    throw InputError(d.path, "a PNG whose image data goes on for more than " +
                                 std::to_string(kMaxBytesAfterImage / 1024) + " KiB past its image's end (at byte " +
                                 std::to_string(d.image_end_at) +
                                 "): a decompression bomb or a faulty encoder, refused rather than inflated");
  if (d.cut_short) {
    if (d.between_chunks) throw InputError(d.path, "a PNG cut short (no IEND chunk at its end: still being written?)");
    throw InputError(d.path, "a PNG cut short or damaged (its " + d.error.chunk_type + " chunk at byte " +
                                 std::to_string(d.error.chunk_at) +
                                 " is longer than the rest of the file: still being written?)");
  }
  const PngDecoding::Said& said = d.refused ? d.refusal : d.error;
  const std::string at_byte = " at byte " + std::to_string(said.chunk_at);
  std::string message(WithoutChunkName(said.message));
  if (message == "CRC error")
    throw InputError(d.path, "a damaged PNG (its " + said.chunk_type + " chunk" + at_byte + " fails its CRC check)");
  if (message == "Not enough image data")  // at the chunk after the image data: not worth naming
    throw InputError(d.path, "a damaged PNG (its image data ends before the image does: " + message + ")");
  if (said.in_header)
    throw InputError(d.path,
                     "a damaged PNG (its chunk" + at_byte + " has no valid type or length: " + said.message + ")");
  if (!d.refused && !d.warnings.empty() && d.warnings_at == said.chunk_at) message = d.warnings + "; " + message;
  const std::string where = said.chunk_type == "IDAT" ? "its image data (IDAT chunk" + at_byte + ")"
                                                      : "its " + said.chunk_type + " chunk" + at_byte;
  throw InputError(d.path, "a damaged PNG (" + where + ": " + message + ")");
}

}  // namespace

std::optional<PngReader> PngReader::Open(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) throw InputError(path, "cannot be opened");
  std::string bytes(size_t(f.tellg()), '\0');
  f.seekg(0);
  if (!f.read(bytes.data(), std::streamsize(bytes.size()))) throw InputError(path, "cannot be read");
  return FromBytes(path, std::move(bytes));
}

std::optional<PngReader> PngReader::FromBytes(const std::string& path, std::string bytes) {
  // A camera creates its image's file before it writes it: named so here,
  // not as another format, for every caller (reconstruct's, calibrate's and
  // check's readers would each say "is not a PNG file").
  if (bytes.empty()) throw InputError(path, "is empty (0 bytes: still being written?)");
  if (bytes.compare(0, kSignature.size(), kSignature) != 0) return std::nullopt;
  auto d = std::make_unique<PngDecoding>();
  d->path = path;
  d->bytes = std::move(bytes);
  d->at = kSignature.size();
  d->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, d.get(), OnError, OnWarning);
  if (d->png == nullptr) throw std::bad_alloc();  // or a libpng other than the headers' (its warning, kept)
  d->info = png_create_info_struct(d->png);
  if (d->info == nullptr) throw std::bad_alloc();
  png_set_read_fn(d->png, d.get(), ReadFromBytes);
  if (!GuardedReadHeader(d->png, d->info)) Refuse(*d);

  png_uint_32 width_px = 0, height_px = 0;
  int bit_depth = 0, colour_type = 0;
  png_get_IHDR(d->png, d->info, &width_px, &height_px, &bit_depth, &colour_type, nullptr, nullptr, nullptr);
  if (width_px > kMaxSidePx || height_px > kMaxSidePx || uint64_t(width_px) * height_px > kMaxPixels)
    throw InputError(path, "a PNG too large to read (its IHDR gives an image of " + std::to_string(width_px) + " x " +
                               std::to_string(height_px) + " px; this reader takes up to " +
                               std::to_string(kMaxSidePx) + " px a side and " + std::to_string(kMaxPixels) +
                               " px in all)");
  PngReader reader(std::move(d));
  reader.width_px_ = width_px;
  reader.height_px_ = height_px;
  reader.bit_depth_ = bit_depth == 16 ? 16 : 8;
  reader.stored_bit_depth_ = bit_depth;
  // OpenCV's PngDecoder::readHeader: a tRNS chunk makes colour and palette
  // images 4-channel; one on a grey image is dropped (png_set_strip_alpha).
  png_bytep trans_alpha = nullptr;
  int num_trans = 0;
  png_color_16p trans_colour = nullptr;
  switch (colour_type) {
    case PNG_COLOR_TYPE_RGB:
    case PNG_COLOR_TYPE_PALETTE:
      png_get_tRNS(reader.decoding_->png, reader.decoding_->info, &trans_alpha, &num_trans, &trans_colour);
      reader.channels_ = num_trans > 0 ? 4 : 3;
      break;
    case PNG_COLOR_TYPE_GRAY_ALPHA:
    case PNG_COLOR_TYPE_RGB_ALPHA:
      reader.channels_ = 4;
      break;
    default:
      reader.channels_ = 1;
  }
  return reader;
}

PngReader::PngReader(std::unique_ptr<PngDecoding> decoding) : decoding_(std::move(decoding)) {}
PngReader::PngReader(PngReader&&) noexcept = default;
PngReader& PngReader::operator=(PngReader&&) noexcept = default;
PngReader::~PngReader() = default;

void PngReader::Read(void* pixels, size_t row_stride_bytes) {
  PngDecoding& d = *decoding_;
  STEREORIG_CHECK(!d.read);
  d.read = true;
  size_t row_bytes = 0;
  if (!GuardedSetUpTransforms(d.png, d.info, channels_, &row_bytes)) Refuse(d);
  // The layout the header promised (FromBytes) is the one libpng writes,
  // checked before it writes a byte.
  STEREORIG_CHECK(row_bytes == size_t(width_px_) * size_t(channels_) * size_t(bit_depth_ / 8));
  STEREORIG_CHECK(row_stride_bytes >= row_bytes);
  std::vector<png_bytep> rows(height_px_);
  for (size_t y = 0; y < rows.size(); ++y) rows[y] = static_cast<png_bytep>(pixels) + y * row_stride_bytes;
  if (!GuardedReadImage(d.png, d.info, rows.data()) || d.refused) Refuse(d);
}

}  // namespace stereorig
