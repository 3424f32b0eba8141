// Is this PNG file whole? Checked from its first and last bytes, without
// decoding: a capture a camera was still writing (cut short) is named in
// one line, where libpng would first print its own "libpng error: Read
// Error" on stderr and the decoder then fail.
#pragma once

#include <string>

namespace stereorig {

// False if `path` does not start with the PNG signature (not a PNG: left to
// the decoder). True if it does and ends with the IEND chunk. Throws
// InputError naming the file if it is a PNG that does not end so (cut short,
// or trailing bytes after the image).
bool CheckPngIsWhole(const std::string& path);

}  // namespace stereorig
