// A strict reader over a parsed YAML mapping: typed getters that name the
// file and key on any error, and Finish(), which rejects keys nobody read.
// Every YAML input of the project (rig file, target file, simulator spec,
// runtime options) goes through it, so a typo in a key is an error, never a
// silently ignored setting.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace stereorig {

class YamlMap {
 public:
  // Parses `path`; throws InputError on a missing file or a syntax error.
  // An empty document (an empty file, comments only, as an options file
  // with every key commented out, or a bare `null` / `~`) is a mapping
  // with no keys: every optional key takes its default, and a required one
  // is reported missing. With `text_read`, the bytes parsed are kept there:
  // the file is read once, so a caller that fingerprints it (stereorig
  // check's CRC-32) fingerprints what was parsed, not a file replaced since.
  static YamlMap LoadFile(const std::string& path, std::string* text_read = nullptr);
  static YamlMap LoadString(const std::string& text, const std::string& where);
  // `node` must be a mapping; `where` is "file: key.path" for messages.
  YamlMap(const YAML::Node& node, std::string file, std::string key_path);

  bool Has(const std::string& key) const;
  double GetDouble(const std::string& key);
  double GetDouble(const std::string& key, double default_value);
  int GetInt(const std::string& key);
  int GetInt(const std::string& key, int default_value);
  bool GetBool(const std::string& key);
  bool GetBool(const std::string& key, bool default_value);
  // An optional key read into *value, which holds its default and keeps it
  // when the key is absent: the field is named once, so a key cannot be read
  // into one field with another's default. Bad values throw as the getters.
  void Read(const std::string& key, double* value) { *value = GetDouble(key, *value); }
  void Read(const std::string& key, int* value) { *value = GetInt(key, *value); }
  void Read(const std::string& key, bool* value) { *value = GetBool(key, *value); }
  std::string GetString(const std::string& key);
  std::string GetString(const std::string& key, const std::string& default_value);
  // A flat sequence of finite numbers; `expected_size` < 0 accepts any length.
  std::vector<double> GetDoubles(const std::string& key, int expected_size = -1);
  std::vector<int> GetInts(const std::string& key, int expected_size = -1);
  // A 4x4 matrix as four rows of four numbers.
  Eigen::Matrix4d GetMatrix4(const std::string& key);
  YamlMap GetMap(const std::string& key);
  // The same, but a key with no value (YAML's null: `match:` with every key
  // under it commented out, or `~`) reads as a mapping with no keys, as an
  // empty document does. Only for sections whose keys all have defaults
  // (the runtime options): in the rig file, target file and the others an
  // empty section is a mistake, and GetMap names it.
  YamlMap GetMapOrEmpty(const std::string& key);
  std::vector<YamlMap> GetMaps(const std::string& key);  // a sequence of mappings
  // The raw node, for shapes the getters above do not cover.
  YAML::Node GetNode(const std::string& key);
  // All keys of this mapping, in file order (marks none as read).
  std::vector<std::string> Keys() const;

  // Throws InputError naming the first key that was never read.
  void Finish() const;

  // "file: key.path" for messages about this mapping or one of its keys.
  std::string Where(const std::string& key = "") const;
  const std::string& file() const { return file_; }

  // Converts a scalar node to a finite double, or throws naming `where`.
  static double ToDouble(const YAML::Node& n, const std::string& where);
  static Eigen::Matrix4d ToMatrix4(const YAML::Node& n, const std::string& where);

 private:
  // The parsed document of LoadFile / LoadString as a mapping (a null
  // document: one with no keys); `where` names it in errors.
  static YamlMap FromDocument(YAML::Node root, const std::string& where);
  YAML::Node Require(const std::string& key);
  // The key of this mapping, not read so far, that is a likely misspelling
  // of `key` (a slip or two of typing from it), or "" if none is.
  std::string MisspeltAs(const std::string& key) const;

  YAML::Node node_;
  std::string file_;
  std::string key_path_;
  std::set<std::string> read_;
};

}  // namespace stereorig
