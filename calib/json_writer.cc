#include "calib/json_writer.h"

#include <cmath>
#include <cstdio>

namespace stereorig {

std::string JsonEscape(const std::string& s) {
  std::string o(1, '"');
  for (char c : s) {
    switch (c) {
      case '"':
        o += "\\\"";
        break;
      case '\\':
        o += "\\\\";
        break;
      case '\n':
        o += "\\n";
        break;
      case '\t':
        o += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", c);
          o += b;
        } else {
          o += c;
        }
    }
  }
  o += '"';
  return o;
}

void JsonWriter::Key(const std::string& key) {
  if (!first_.empty()) {
    if (!first_.back()) out_ += ",";
    first_.back() = false;
    out_ += '\n';
    out_.append(2 * first_.size(), ' ');
  }
  if (!key.empty()) out_ += JsonEscape(key) + ": ";
}

JsonWriter& JsonWriter::BeginObject(const std::string& key) {
  Key(key);
  out_ += "{";
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::EndObject() {
  first_.pop_back();
  out_ += '\n';
  out_.append(2 * first_.size(), ' ');
  out_ += '}';
  return *this;
}
JsonWriter& JsonWriter::BeginArray(const std::string& key) {
  Key(key);
  out_ += "[";
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::EndArray() {
  first_.pop_back();
  out_ += '\n';
  out_.append(2 * first_.size(), ' ');
  out_ += ']';
  return *this;
}
JsonWriter& JsonWriter::Number(const std::string& key, double v) {
  Key(key);
  if (!std::isfinite(v)) {
    out_ += "null";
  } else {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", v);
    out_ += b;
  }
  return *this;
}
JsonWriter& JsonWriter::Int(const std::string& key, long v) {
  Key(key);
  out_ += std::to_string(v);
  return *this;
}
JsonWriter& JsonWriter::String(const std::string& key, const std::string& v) {
  Key(key);
  out_ += JsonEscape(v);
  return *this;
}
JsonWriter& JsonWriter::Bool(const std::string& key, bool v) {
  Key(key);
  out_ += v ? "true" : "false";
  return *this;
}
JsonWriter& JsonWriter::Numbers(const std::string& key, const std::vector<double>& v) {
  BeginArray(key);
  for (double x : v) Number(x);
  return EndArray();
}

}  // namespace stereorig
