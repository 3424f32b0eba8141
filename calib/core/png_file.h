// Is this PNG file whole and undamaged? Checked chunk by chunk without
// decoding the image (its data is inflated and counted, not kept): a capture
// a camera was still writing (cut short) or one with a damaged byte is named
// in one line, where libpng would first print its own line on stderr
// ("libpng error: Read Error", "bad adaptive filter value", "IDAT: invalid
// distance too far back") and the decoder then fail.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace stereorig {

// False if `path` does not start with the PNG signature (not a PNG: left to
// the decoder). True if it does and its chunks, IHDR first, each lie within
// the file and match their CRC, up to IEND (libpng ignores bytes after it),
// and its image data inflates to the bytes its IHDR's image needs (more, or
// bytes after the stream, pass: libpng reads the image whole with a
// warning; an image over 2^30 px is not inflated, the decoder refusing it:
// png_image_data.h). Throws InputError naming the file otherwise: cut short
// (a chunk runs past the end, or no IEND), too large (over 10^6 px a side)
// or damaged (a CRC that fails, a chunk type that is not 4 letters, an IHDR
// PNG does not define, image data that does not inflate, inflates to too few
// bytes, or whose IDAT chunks are not consecutive). Not checked: the inflated rows' filter
// bytes (zlib's Adler-32 over them has already caught damage; a wrong one
// under a valid checksum is an encoder's bug): the decoder's to find.
bool CheckPngIsWhole(const std::string& path);

// The CRC-32 of ISO 3309 (zlib's crc32) over `bytes`, as a PNG chunk
// stores it over its type and data.
uint32_t PngCrc(std::string_view bytes);

}  // namespace stereorig
