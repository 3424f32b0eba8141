// Is this PNG file whole and undamaged? Checked chunk by chunk without
// decoding: a capture a camera was still writing (cut short) or one with a
// damaged byte is named in one line, where libpng would first print its own
// line on stderr ("libpng error: Read Error", "bad adaptive filter value")
// and the decoder then fail.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace stereorig {

// False if `path` does not start with the PNG signature (not a PNG: left to
// the decoder). True if it does and its chunks, IHDR first, each lie within
// the file and match their CRC, up to IEND (libpng ignores bytes after it).
// Throws InputError naming the file otherwise: cut short (a chunk runs past
// the end, or no IEND) or damaged (a CRC that fails, a chunk type that is
// not 4 letters). Not checked: a compressed image stream that is wrong
// under valid CRCs (an encoder's bug, not damage): the decoder's to find.
bool CheckPngIsWhole(const std::string& path);

// The CRC-32 of ISO 3309 (zlib's crc32) over `bytes`, as a PNG chunk
// stores it over its type and data.
uint32_t PngCrc(std::string_view bytes);

}  // namespace stereorig
