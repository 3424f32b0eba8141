// A PNG's image data checked as CheckPngIsWhole (png_file.h) streams past its
// chunks: the IDAT chunks' data, concatenated, must be one zlib stream that
// inflates without error to at least the bytes the IHDR's image needs, and
// then ends (Z_STREAM_END) or gives more. Damage under valid CRCs (a file
// rewritten by a faulty tool, a copy whose CRCs were redone) is then named
// in one line, where libpng would first print its own ("libpng error: IDAT:
// invalid distance too far back", "Not enough image data").
//
// What libpng 1.6 reads whole is passed, though it warns: bytes after the
// stream's end ("libpng warning: IDAT: Extra compressed data") and a stream
// that inflates to more than the image ("IDAT: Too much image data"). So
// inflating stops one byte past the image's bytes: a small file whose stream
// would inflate to gigabytes (a deflate bomb) costs no more than its image.
// libpng reads on to the stream's end, warning of damage past the image
// ("IDAT: incorrect data check"), but refuses a stream that gives more than
// the image and is then cut short ("Not enough image data"): that passes
// here, to be refused by the decoder in its own line.
//
// An image larger than the decoder reads is refused or left alone before
// any inflating (kMaxPixels). Streaming: the inflated bytes go into a small
// scratch buffer and are counted, never kept. Not free: the decoder inflates
// the same data again, and inflating is much of decoding (a demo capture,
// 752 x 582 px: ~2 ms more per image, against imread's 4-4.8 ms on the same
// machine).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

struct z_stream_s;  // zlib's, which only this library links

namespace stereorig {

// The bytes a PNG's image data inflates to: for each row one filter-type
// byte and the row's packed pixels; for an interlaced (Adam7) image, the
// same for each of the seven passes' sub-images (a pass without a pixel has
// no row). `channels`: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA, 1 palette.
// Saturates at UINT64_MAX where the count does not fit (from about 2^31 px a
// side at 64 bits a pixel), beyond any image the decoder reads.
uint64_t PngImageDataBytes(uint32_t width_px, uint32_t height_px, int bit_depth, int channels, bool interlaced);

class PngImageData {
 public:
  // libpng's default limit on each side (PNG_USER_WIDTH_MAX and
  // PNG_USER_HEIGHT_MAX in /usr/include/libpng16/pnglibconf.h, 1.6.39 on
  // Debian 12), which OpenCV does not raise: beyond it libpng prints
  // "libpng warning: Image width exceeds user limit in IHDR" and "libpng
  // error: Invalid IHDR data". PNG itself allows up to 2^31 - 1 px.
  static constexpr uint32_t kMaxSidePx = 1000000;
  // OpenCV's imread refuses an image of more pixels from its header alone,
  // in an exception (the default of OPENCV_IO_MAX_IMAGE_PIXELS; reconstruct/
  // image_file.cc names the file with it). Its image data is then not
  // inflated here: the check would do more work than the decoder.
  static constexpr uint64_t kMaxPixels = uint64_t(1) << 30;

  // `ihdr`: the IHDR chunk's data. Throws InputError naming `path` if it is
  // not a header libpng accepts (13 bytes, a width and height of 1 to
  // kMaxSidePx, a colour type and bit depth PNG defines, compression and
  // filter method 0, interlace 0 or 1). Over kMaxPixels, the image data is
  // not checked (Add and Finish only see that the IDATs are in place).
  PngImageData(const std::string& path, std::string_view ihdr);
  ~PngImageData();
  PngImageData(const PngImageData&) = delete;
  PngImageData& operator=(const PngImageData&) = delete;

  // One IDAT chunk's data, `at` its chunk's byte offset (for the message).
  // Throws InputError naming the file if the stream is damaged, or if the
  // IDAT comes after another chunk that followed the IDATs (that chunk
  // named if the stream had not yet given the image).
  void Add(std::string_view idat_data, uint64_t at);
  // At each chunk other than IDAT and IEND after an IDAT: its type and byte
  // offset, named if an IDAT follows.
  void Interrupt(std::string_view chunk_type, uint64_t at);
  // At IEND: throws InputError naming the file if there was no IDAT, or the
  // stream inflated to fewer bytes than the IHDR's image needs or did not
  // end once it had them.
  void Finish();
  // Whether an IDAT chunk came.
  bool started() const { return started_; }

 private:
  [[noreturn]] void Fail(const std::string& problem) const;

  std::string path_;
  uint32_t width_px_ = 0, height_px_ = 0;
  uint64_t expected_bytes_ = 0, inflated_bytes_ = 0;
  std::unique_ptr<z_stream_s> stream_;  // null for an image over kMaxPixels: not inflated
  // `ended_`: the stream ended, or gave more than the image (no more inflated).
  bool started_ = false, ended_ = false, finished_ = false;
  std::string interrupted_by_;  // "its tEXt chunk at byte N": the first chunk after the IDATs
  std::vector<unsigned char> scratch_;
};

}  // namespace stereorig
