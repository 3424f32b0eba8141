#include "calib/json_writer.h"

#include <cmath>

#include "calib/core/input_error.h"
#include "calib/json_text.h"

namespace stereorig {

nlohmann::ordered_json* JsonWriter::Add(const std::string& key, nlohmann::ordered_json value) {
  if (open_.empty()) {
    STEREORIG_CHECK(root_.is_null() && key.empty());
    root_ = std::move(value);
    return &root_;
  }
  nlohmann::ordered_json& parent = *open_.back();
  if (parent.is_array()) {
    STEREORIG_CHECK(key.empty());
    parent.push_back(std::move(value));
    return &parent.back();
  }
  STEREORIG_CHECK(parent.is_object() && !key.empty());
  parent[key] = std::move(value);
  return &parent[key];
}

JsonWriter& JsonWriter::BeginObject(const std::string& key) {
  open_.push_back(Add(key, nlohmann::ordered_json::object()));
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  STEREORIG_CHECK(!open_.empty() && open_.back()->is_object());
  open_.pop_back();
  return *this;
}

JsonWriter& JsonWriter::BeginArray(const std::string& key) {
  open_.push_back(Add(key, nlohmann::ordered_json::array()));
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  STEREORIG_CHECK(!open_.empty() && open_.back()->is_array());
  open_.pop_back();
  return *this;
}

JsonWriter& JsonWriter::Number(const std::string& key, double v) {
  Add(key, std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr));
  return *this;
}

JsonWriter& JsonWriter::Int(const std::string& key, long v) {
  Add(key, v);
  return *this;
}

JsonWriter& JsonWriter::String(const std::string& key, const std::string& v) {
  Add(key, v);
  return *this;
}

JsonWriter& JsonWriter::Bool(const std::string& key, bool v) {
  Add(key, v);
  return *this;
}

JsonWriter& JsonWriter::Numbers(const std::string& key, const std::vector<double>& v) {
  BeginArray(key);
  for (double x : v) Number(x);
  return EndArray();
}

const std::string& JsonWriter::str() const {
  STEREORIG_CHECK(open_.empty());
  text_ = JsonReportText(root_);
  return text_;
}

}  // namespace stereorig
