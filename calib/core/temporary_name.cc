#include "calib/core/temporary_name.h"

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// The longest start of `text` of at most `max_bytes` bytes that does not end
// inside a UTF-8 character. A UTF-8 character is at most 4 bytes: bytes that
// are not UTF-8 are cut as they fall.
std::string StartWithin(const std::string& text, size_t max_bytes) {
  if (text.size() <= max_bytes) return text;
  // text[keep], the first byte cut off, must start a character.
  auto continues = [&](size_t i) { return (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80; };
  size_t keep = max_bytes;
  while (keep > 0 && max_bytes - keep < 3 && continues(keep)) --keep;
  if (continues(keep)) keep = max_bytes;  // no UTF-8 character starts near: not UTF-8
  return text.substr(0, keep);
}

}  // namespace

std::string TemporaryName(const std::string& prefix, const std::string& name, const std::string& suffix) {
  STEREORIG_CHECK(prefix.size() + suffix.size() < kMaxNameBytes);
  const size_t room = kMaxNameBytes - prefix.size() - suffix.size();
  if (name.size() <= room) return prefix + name + suffix;
  const size_t dot = name.rfind('.');
  const bool keep_extension = dot != std::string::npos && dot > 0 && name.size() - dot <= room / 2;
  const std::string extension = keep_extension ? name.substr(dot) : "";
  const std::string head = name.substr(0, name.size() - extension.size());
  return prefix + StartWithin(head, room - extension.size()) + extension + suffix;
}

}  // namespace stereorig
