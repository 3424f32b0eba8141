#include "calib/json_text.h"

#include <cstdio>

#include "calib/core/utf8_sequence.h"

namespace stereorig {

namespace {

bool IsUtf8(const std::string& text) {
  for (size_t i = 0; i < text.size();) {
    const size_t n = Utf8SequenceLength(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

// A copy of `value` whose strings, member names too, are UTF-8.
template <typename Json>
Json WithUtf8Strings(const Json& value) {
  if (value.is_string()) {
    const auto& s = value.template get_ref<const std::string&>();
    return IsUtf8(s) ? value : Json(Utf8OrEscapedBytes(s));
  }
  if (value.is_array()) {
    Json out = Json::array();
    for (const Json& item : value) out.push_back(WithUtf8Strings(item));
    return out;
  }
  if (value.is_object()) {
    Json out = Json::object();
    for (auto it = value.begin(); it != value.end(); ++it) out[Utf8OrEscapedBytes(it.key())] = WithUtf8Strings(*it);
    return out;
  }
  return value;
}

template <typename Json>
std::string ReportText(const Json& document) {
  return WithUtf8Strings(document).dump(2);
}

}  // namespace

std::string Utf8OrEscapedBytes(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const size_t n = Utf8SequenceLength(text, i);
    if (n > 0) {
      out.append(text, i, n);
      i += n;
      continue;
    }
    char escaped[8];
    std::snprintf(escaped, sizeof escaped, "\\x%02X", static_cast<unsigned char>(text[i]));
    out += escaped;
    ++i;
  }
  return out;
}

std::string JsonReportText(const nlohmann::json& document) { return ReportText(document); }
std::string JsonReportText(const nlohmann::ordered_json& document) { return ReportText(document); }

}  // namespace stereorig
