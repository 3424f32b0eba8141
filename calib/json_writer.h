// A streaming builder for the calibration report's JSON: objects, arrays,
// numbers (NaN and Inf as null), strings and booleans, keys in the order
// given. It builds an nlohmann::ordered_json document (nlohmann-json3-dev)
// and lets that library do the escaping and number formatting; the builder
// interface keeps the report code a flat list of keys and values.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace stereorig {

class JsonWriter {
 public:
  // `key` is the member name inside an object and must be empty inside an
  // array or for the document itself.
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
  // The document as calib/json_text.h writes every report.
  const std::string& str() const;
  const nlohmann::ordered_json& document() const { return root_; }

 private:
  // Adds `value` under `key` to the innermost open container (or as the
  // document) and returns where it now lives.
  nlohmann::ordered_json* Add(const std::string& key, nlohmann::ordered_json value);
  nlohmann::ordered_json root_;
  // The open containers, outermost first. Only the innermost one grows, so
  // the pointers to its ancestors stay valid.
  std::vector<nlohmann::ordered_json*> open_;
  mutable std::string text_;
};

}  // namespace stereorig
