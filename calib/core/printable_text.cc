#include "calib/core/printable_text.h"

#include <cstdio>

namespace stereorig {

// The message with every byte a terminal would not show as text written as
// \xNN: control bytes, and bytes that are not valid UTF-8 (a binary file
// given where YAML or text was expected puts its bytes into the parser's
// message). Valid UTF-8 (a path with 'å') passes unchanged.
std::string PrintableText(const std::string& message) {
  std::string out;
  auto escape = [&out](unsigned char c) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", c);
    out += buf;
  };
  for (size_t i = 0; i < message.size();) {
    const auto c = static_cast<unsigned char>(message[i]);
    if (c < 0x20 || c == 0x7F) {
      escape(c);
      ++i;
      continue;
    }
    if (c < 0x80) {
      out += message[i++];
      continue;
    }
    // A UTF-8 sequence as RFC 3629 defines it: the lead byte says how many
    // continuation bytes (10xxxxxx) follow and bounds the first of them, so
    // that overlong forms (E0 80..9F, F0 80..8F), surrogates (ED A0..BF)
    // and code points past U+10FFFF (F4 90..) are escaped as the bytes they
    // are. C1 controls (U+0080..U+009F: C2 80..9F) act on some terminals
    // (U+009B is CSI): escaped too.
    const size_t n = c >= 0xC2 && c <= 0xDF ? 1 : c >= 0xE0 && c <= 0xEF ? 2 : c >= 0xF0 && c <= 0xF4 ? 3 : 0;
    const unsigned char first_min = c == 0xC2 ? 0xA0 : c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80;
    const unsigned char first_max = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
    bool valid = n > 0;
    for (size_t k = 1; valid && k <= n; ++k) {
      if (i + k >= message.size()) {
        valid = false;
        break;
      }
      const auto b = static_cast<unsigned char>(message[i + k]);
      valid = k == 1 ? b >= first_min && b <= first_max : (b & 0xC0) == 0x80;
    }
    if (!valid) {
      escape(c);
      ++i;
      continue;
    }
    out.append(message, i, n + 1);
    i += n + 1;
  }
  return out;
}

}  // namespace stereorig
