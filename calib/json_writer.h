// A minimal JSON writer for reports: objects, arrays, numbers (%.17g, NaN and
// Inf as null), strings (escaped) and booleans. Keys are written in the order
// given.
#pragma once

#include <string>
#include <vector>

namespace stereorig {

class JsonWriter {
 public:
  JsonWriter& BeginObject(const std::string& key = "");
  JsonWriter& EndObject();
  JsonWriter& BeginArray(const std::string& key = "");
  JsonWriter& EndArray();
  JsonWriter& Number(const std::string& key, double v);
  JsonWriter& Number(double v) { return Number("", v); }
  JsonWriter& Int(const std::string& key, long v);
  JsonWriter& Int(long v) { return Int("", v); }
  JsonWriter& String(const std::string& key, const std::string& v);
  JsonWriter& Bool(const std::string& key, bool v);
  JsonWriter& Numbers(const std::string& key, const std::vector<double>& v);
  const std::string& str() const { return out_; }

 private:
  void Key(const std::string& key);
  std::string out_;
  std::vector<bool> first_;  // per open container: nothing written yet
};

std::string JsonEscape(const std::string& s);

}  // namespace stereorig
