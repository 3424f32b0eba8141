#include "calib/core/float_tiff.h"

#include <tiffio.h>

#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// libtiff's first error, kept for the one line (later ones follow from it);
// its warnings dropped (unknown tags, and the like: the samples decide).
struct TiffMessages {
  std::string error;
};

int KeepError(TIFF*, void* user_data, const char* module, const char* format, va_list args) {
  auto& messages = *static_cast<TiffMessages*>(user_data);
  if (messages.error.empty()) {
    char text[512];
    std::vsnprintf(text, sizeof text, format, args);
    try {  // bad_alloc must not unwind through libtiff's C frames (the message is then lost, not the failure)
      messages.error = (module != nullptr && *module != '\0' ? std::string(module) + ": " : std::string()) + text;
    } catch (...) {
    }
  }
  return 1;  // handled: libtiff's global handler (stderr) is not called
}

int DropWarning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

struct TiffCloser {
  void operator()(TIFF* tiff) const { TIFFClose(tiff); }
};
using TiffFile = std::unique_ptr<TIFF, TiffCloser>;

TiffFile Open(const std::string& path, const char* mode, TiffMessages* messages) {
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  if (options == nullptr) throw std::bad_alloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, KeepError, messages);
  TIFFOpenOptionsSetWarningHandlerExtR(options, DropWarning, messages);
  TiffFile tiff(TIFFOpenExt(path.c_str(), mode, options));
  TIFFOpenOptionsFree(options);
  return tiff;
}

std::string Said(const TiffMessages& messages) {
  return messages.error.empty() ? std::string() : " (libtiff: " + messages.error + ")";
}

}  // namespace

bool StartsAsTiff(const std::string& bytes) {
  return bytes.compare(0, 4, std::string("II*\0", 4)) == 0 || bytes.compare(0, 4, std::string("MM\0*", 4)) == 0 ||
         bytes.compare(0, 4, std::string("II+\0", 4)) == 0 || bytes.compare(0, 4, std::string("MM\0+", 4)) == 0;
}

FloatImage ReadFloatTiff(const std::string& path,
                         const std::function<void(uint32_t width_px, uint32_t height_px)>& before_decoding) {
  TiffMessages messages;
  TiffFile tiff = Open(path, "r", &messages);
  if (!tiff) throw InputError(path, "cannot be read as a TIFF file" + Said(messages));
  uint32_t width_px = 0, height_px = 0;
  uint16_t bits = 0, format = SAMPLEFORMAT_UINT, channels = 1, planar = PLANARCONFIG_CONTIG;
  if (TIFFGetField(tiff.get(), TIFFTAG_IMAGEWIDTH, &width_px) != 1 ||
      TIFFGetField(tiff.get(), TIFFTAG_IMAGELENGTH, &height_px) != 1)
    throw InputError(path, "a damaged TIFF (no image size)" + Said(messages));
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_SAMPLESPERPIXEL, &channels);
  TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_PLANARCONFIG, &planar);
  if (bits != 32 || format != SAMPLEFORMAT_IEEEFP || channels != 1)
    throw InputError(path, "a TIFF of " + std::to_string(channels) + " channel(s) of " + std::to_string(bits) +
                               "-bit " +
                               (format == SAMPLEFORMAT_IEEEFP ? "float"
                                : format == SAMPLEFORMAT_INT  ? "signed integer"
                                : format == SAMPLEFORMAT_UINT ? "integer"
                                                              : "other") +
                               " samples; only float32 single-channel TIFFs are read (depth maps)");
  if (TIFFIsTiled(tiff.get())) throw InputError(path, "a tiled TIFF; only TIFFs in strips are read");
  if (width_px == 0 || height_px == 0 || uint64_t(width_px) * height_px > kMaxFloatTiffPixels)
    throw InputError(path, "a TIFF of " + std::to_string(width_px) + " x " + std::to_string(height_px) +
                               " px; this reader takes 1 to " + std::to_string(kMaxFloatTiffPixels) + " px");
  if (TIFFScanlineSize(tiff.get()) != tmsize_t(width_px) * tmsize_t(sizeof(float)))
    throw InputError(path, "a damaged TIFF (its rows are not " + std::to_string(width_px) + " floats)");
  if (before_decoding) before_decoding(width_px, height_px);
  FloatImage image;
  image.width_px = width_px;
  image.height_px = height_px;
  image.values.resize(size_t(width_px) * height_px);
  for (uint32_t y = 0; y < height_px; ++y) {
    if (TIFFReadScanline(tiff.get(), image.values.data() + size_t(y) * width_px, y, 0) != 1)
      throw InputError(path, "a TIFF cut short or damaged (row " + std::to_string(y) + " of " +
                                 std::to_string(height_px) + " cannot be read)" + Said(messages));
  }
  return image;
}

void WriteFloatTiff(const std::string& path, uint32_t width_px, uint32_t height_px, const float* pixels,
                    size_t row_stride_bytes) {
  TiffMessages messages;
  TiffFile tiff = Open(path, "w", &messages);
  if (!tiff) throw InputError(path, "cannot write the TIFF file" + Said(messages));
  TIFFSetField(tiff.get(), TIFFTAG_IMAGEWIDTH, width_px);
  TIFFSetField(tiff.get(), TIFFTAG_IMAGELENGTH, height_px);
  TIFFSetField(tiff.get(), TIFFTAG_BITSPERSAMPLE, 32);
  TIFFSetField(tiff.get(), TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP);
  TIFFSetField(tiff.get(), TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tiff.get(), TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tiff.get(), TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tiff.get(), TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  TIFFSetField(tiff.get(), TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(tiff.get(), 0));
  // libtiff may change the row it is given (byte-swapped for another byte
  // order, a predictor's differences): each row goes through a copy.
  std::vector<float> row(width_px);
  for (uint32_t y = 0; y < height_px; ++y) {
    std::memcpy(row.data(), reinterpret_cast<const char*>(pixels) + y * row_stride_bytes, width_px * sizeof(float));
    if (TIFFWriteScanline(tiff.get(), row.data(), y, 0) != 1)
      throw InputError(path, "cannot write the TIFF file" + Said(messages));
  }
  TIFF* file = tiff.release();
  // TIFFClose writes the directory; a failure there (a full disk) is the
  // file's last write: TIFFFlush first, to see it.
  const bool flushed = TIFFFlush(file) == 1;
  TIFFClose(file);
  if (!flushed) throw InputError(path, "cannot write the TIFF file" + Said(messages));
}

}  // namespace stereorig
