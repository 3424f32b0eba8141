// Where text is well-formed UTF-8: what error lines (calib/core/printable_text.h's
// PrintableText) and JSON reports (calib/json_text.h) escape as \xNN is the
// bytes that are not. A Linux path may hold any byte but '/' and NUL (a
// Latin-1 'é' is the one byte E9), so paths are not UTF-8 as given.
#pragma once

#include <cstddef>
#include <string>

namespace stereorig {

// The length (1 to 4) of the well-formed UTF-8 sequence starting at text[i],
// or 0 when the byte there starts none (a lone continuation byte, a lead
// byte without its continuation bytes, an overlong form, a surrogate, a code
// point past U+10FFFF: RFC 3629). ASCII is 1, control bytes included.
size_t Utf8SequenceLength(const std::string& text, size_t i);

}  // namespace stereorig
