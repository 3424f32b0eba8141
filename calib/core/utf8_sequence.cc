#include "calib/core/utf8_sequence.h"

namespace stereorig {

size_t Utf8SequenceLength(const std::string& text, size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  if (c < 0x80) return 1;
  // The lead byte says how many continuation bytes (10xxxxxx) follow and
  // bounds the first of them, so that overlong forms (C0, C1, E0 80..9F,
  // F0 80..8F), surrogates (ED A0..BF) and code points past U+10FFFF
  // (F4 90.., F5..FF) are no sequence.
  const size_t n = c >= 0xC2 && c <= 0xDF ? 1 : c >= 0xE0 && c <= 0xEF ? 2 : c >= 0xF0 && c <= 0xF4 ? 3 : 0;
  if (n == 0 || i + n >= text.size()) return 0;
  const unsigned char first_min = c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80;
  const unsigned char first_max = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
  for (size_t k = 1; k <= n; ++k) {
    const auto b = static_cast<unsigned char>(text[i + k]);
    if (k == 1 ? b < first_min || b > first_max : (b & 0xC0) != 0x80) return 0;
  }
  return n + 1;
}

}  // namespace stereorig
