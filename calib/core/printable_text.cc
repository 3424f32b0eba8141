#include "calib/core/printable_text.h"

#include <cstdio>

#include "calib/core/utf8_sequence.h"

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
    // Bytes that are not well-formed UTF-8 are escaped as the bytes they
    // are. C1 controls (U+0080..U+009F: C2 80..9F) act on some terminals
    // (U+009B is CSI): escaped too.
    const size_t n = Utf8SequenceLength(message, i);
    const bool c1_control = c == 0xC2 && static_cast<unsigned char>(message[i + 1]) < 0xA0;
    if (n == 0 || c1_control) {
      escape(c);
      ++i;
      continue;
    }
    out.append(message, i, n);
    i += n;
  }
  return out;
}

}  // namespace stereorig
