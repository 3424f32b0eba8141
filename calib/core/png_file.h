// Is this PNG file whole? Checked from its first and last bytes, without
// decoding: a capture a camera was still writing (cut short) is named in
// one line, where libpng would first print its own "libpng error: Read
// Error" on stderr and the decoder then fail.
#pragma once

#include <string>

namespace stereorig {

// False if `path` does not start with the PNG signature (not a PNG: left to
// the decoder). True if it does and its IEND chunk closes it (within its
// last 4 KiB: libpng ignores bytes after it). Throws InputError naming the
// file if it is a PNG without one there (cut short).
bool CheckPngIsWhole(const std::string& path);

}  // namespace stereorig
