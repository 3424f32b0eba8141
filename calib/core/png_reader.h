// One PNG file read once, by libpng, with every way it can be unreadable
// bad input (InputError) in one line naming the file, and nothing of
// libpng's own on stderr: a capture a camera was still writing (cut short),
// one with a flipped byte (a chunk's CRC, or the image data's Adler-32 under
// CRCs redone by a faulty tool), a header PNG does not define, an image too
// large. Where OpenCV's imread would print "libpng error: Read Error" or
// "libpng warning: IDAT: incorrect data check" and then fail or, for the
// second, return the damaged pixels.
//
// Decoded as imread(path, IMREAD_UNCHANGED) decodes it (OpenCV 4.6's
// grfmt_png.cpp: the same libpng transforms), byte for byte, so that the
// callers that wrap it in a cv::Mat (reconstruct/image_file.h,
// calib/capture_folder.cc) read what they read before. The full libpng API,
// not the simplified one (png_image): that one converts by the file's gAMA
// chunk (a grey 40 under gAMA 1.0 reads as 110, as sRGB) and 16 bits to
// linear light, where imread takes the samples as stored, and it reads only
// as one of its own formats.
//
// One decode, where its predecessor checked the file with a chunk walker
// and an inflate of its own before imread decoded it all again: a demo
// capture image (752 x 582 px grey, ~250 KB) reads in a median 4.4 ms,
// against 6.8-7.1 ms for the check and imread, 4.8-4.9 ms for imread alone
// (1000 reads of the demo's 20 active captures' images, 2 busy cores).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace stereorig {

struct PngDecoding;  // libpng's state and this reader's record of its messages

class PngReader {
 public:
  // libpng's default limit on a side (PNG_USER_WIDTH_MAX and
  // PNG_USER_HEIGHT_MAX, /usr/include/libpng16/pnglibconf.h, 1.6.39 on
  // Debian 12), which imread keeps too. PNG itself allows 2^31 - 1 px.
  static constexpr uint32_t kMaxSidePx = 1000000;
  // This reader's own limit on the pixels: 2^28 (268 Mpx; 16384 x 16384),
  // above the largest machine-vision sensors (~250 Mpx) and 600 times a
  // demo capture, so that a header alone cannot make it claim more than
  // 2 GiB (16-bit RGBA, 8 bytes a pixel) before any image data is read.
  // imread's limit (OPENCV_IO_MAX_IMAGE_PIXELS) was 2^30.
  static constexpr uint64_t kMaxPixels = uint64_t(1) << 28;

  // The PNG at `path`, read up to its image data; nullopt if the file does
  // not start with PNG's signature (another format, or no image). Throws
  // InputError naming the file if it cannot be read, is empty ("is empty (0
  // bytes: still being written?)", whatever its name), or if what comes
  // before the image data is cut short, damaged (a chunk's CRC, a header
  // PNG does not define) or gives an image over kMaxSidePx a side or
  // kMaxPixels.
  static std::optional<PngReader> Open(const std::string& path);
  // The same for a file's bytes already read, `path` naming it in messages.
  static std::optional<PngReader> FromBytes(const std::string& path, std::string bytes);

  PngReader(PngReader&&) noexcept;
  PngReader& operator=(PngReader&&) noexcept;
  ~PngReader();

  // The image as it decodes, from its header. Channels as imread gives
  // them: 1 grey; 3 B, G, R (colour, or a palette); 4 B, G, R, A (colour
  // with alpha or a tRNS chunk; grey with alpha as G, G, G, A). Bit depth
  // 8 or 16; grey of 1, 2 or 4 bits is scaled to 8 (1-bit white is 255).
  uint32_t width_px() const { return width_px_; }
  uint32_t height_px() const { return height_px_; }
  int channels() const { return channels_; }
  int bit_depth() const { return bit_depth_; }
  // The file's own bit depth (IHDR: 1, 2, 4, 8 or 16), before the scaling
  // above: what tells a 1-, 2- or 4-bit grey capture from an 8-bit one.
  int stored_bit_depth() const { return stored_bit_depth_; }

  // Decodes the image into `pixels`: height_px() rows, each of width_px() x
  // channels() samples (uint8_t, or uint16_t in the machine's byte order),
  // row y starting at pixels + y * row_stride_bytes. Once only. Throws
  // InputError naming the file if the image data is cut short or damaged
  // (see png_reader.cc for which of libpng's warnings are taken as damage),
  // or goes on for more than 16 KiB past the image's last row (a deflate
  // bomb, which libpng would inflate to its end: png_reader.cc,
  // kMaxBytesAfterImage); the pixels are then not to be used.
  void Read(void* pixels, size_t row_stride_bytes);

 private:
  explicit PngReader(std::unique_ptr<PngDecoding> decoding);

  std::unique_ptr<PngDecoding> decoding_;
  uint32_t width_px_ = 0, height_px_ = 0;
  int channels_ = 0, bit_depth_ = 0, stored_bit_depth_ = 0;
};

}  // namespace stereorig
