// A PNG's image data checked as CheckPngIsWhole (png_file.h) streams past its
// chunks: the IDAT chunks' data, concatenated, must be one zlib stream that
// inflates without error, ends (Z_STREAM_END) with the last IDAT, and
// inflates to exactly the bytes the IHDR's image needs. Damage under valid
// CRCs (a file rewritten by a faulty tool, a copy whose CRCs were redone)
// is then named in one line, where libpng would first print its own
// ("libpng error: IDAT: invalid distance too far back").
//
// Streaming: the inflated bytes go into a small scratch buffer and are
// counted, never kept. Not free: the decoder inflates the same data again,
// and inflating is much of decoding (a demo capture, 752 x 582 px: ~2 ms
// more per image, against imread's 4-4.8 ms on the same machine).
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
uint64_t PngImageDataBytes(uint32_t width_px, uint32_t height_px, int bit_depth, int channels, bool interlaced);

class PngImageData {
 public:
  // `ihdr`: the IHDR chunk's data. Throws InputError naming `path` if it is
  // not a header libpng accepts (13 bytes, a width and height of 1 to
  // 2^31 - 1 px, a colour type and bit depth PNG defines, compression and
  // filter method 0, interlace 0 or 1).
  PngImageData(const std::string& path, std::string_view ihdr);
  ~PngImageData();
  PngImageData(const PngImageData&) = delete;
  PngImageData& operator=(const PngImageData&) = delete;

  // One IDAT chunk's data, `at` its chunk's byte offset (for the message).
  // Throws InputError naming the file if the stream is damaged, goes on
  // after its end, or resumes after another chunk came between the IDATs.
  void Add(std::string_view idat_data, uint64_t at);
  // At the chunk after the last IDAT (or at IEND): throws InputError naming
  // the file if there was no IDAT, the stream did not end, or it inflated
  // to another number of bytes than the IHDR's image needs.
  void Finish();
  // Whether an IDAT chunk came.
  bool started() const { return started_; }

 private:
  [[noreturn]] void Fail(const std::string& problem) const;

  std::string path_;
  uint32_t width_px_ = 0, height_px_ = 0;
  uint64_t expected_bytes_ = 0, inflated_bytes_ = 0;
  std::unique_ptr<z_stream_s> stream_;
  bool started_ = false, ended_ = false, finished_ = false;
  std::vector<unsigned char> scratch_;
};

}  // namespace stereorig
