#include "yaml_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "input_error.h"
#include "input_file.h"

namespace stereorig {

namespace {

// yaml-cpp's parse error, named by `where` and the line it points to (a
// file read whole or a string: the same line numbers).
InputError SyntaxError(const std::string& where, const YAML::Exception& e) {
  std::string line;
  if (!e.mark.is_null()) line = " (line " + std::to_string(e.mark.line + 1) + ")";
  return InputError(where, "not valid YAML: " + e.msg + line);
}

}  // namespace

YamlMap YamlMap::LoadFile(const std::string& path, std::string* text_read) {
  RequireInputFile(path, /*pipe_too=*/true);  // read once, start to end
  // Read here, not by yaml-cpp's LoadFile, whose error for a file it cannot
  // open is "bad file" (an unreadable file read "not valid YAML: bad file").
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot be read: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, "cannot be read to its end");
  if (text_read == nullptr) return LoadString(text.str(), path);
  *text_read = text.str();
  return LoadString(*text_read, path);
}

YamlMap YamlMap::LoadString(const std::string& text, const std::string& where) {
  // Every document, not yaml-cpp's Load (the first alone): a file's keys
  // after a `---` were never read nor checked, typos included, in every
  // strict reader (rig, target, layout, simulator spec, certificates). A
  // file is one mapping; an empty later document (a trailing `---`) is none.
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    throw SyntaxError(where, e);
  }
  for (size_t k = 1; k < documents.size(); ++k)
    if (!documents[k].IsNull())
      throw InputError(where, "line " + std::to_string(documents[k].Mark().line + 1) +
                                  ": a second YAML document (after `---`): the file is one mapping; remove the "
                                  "`---`, or merge its keys into the first document");
  return FromDocument(documents.empty() ? YAML::Node() : documents[0], where);
}

YamlMap YamlMap::FromDocument(YAML::Node root, const std::string& where) {
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);  // empty, or comments only: no keys
  if (!root.IsMap()) throw InputError(where, "expected a YAML mapping at the top level");
  return YamlMap(root, where, "");
}

YamlMap::YamlMap(const YAML::Node& node, std::string file, std::string key_path)
    : node_(node), file_(std::move(file)), key_path_(std::move(key_path)) {
  if (!node_.IsMap()) throw InputError(Where(), "expected a mapping");
  // yaml-cpp keeps a repeated key's first value and drops the rest without
  // a word: "units: mm" then "units: m" would read as mm.
  std::set<std::string> keys;
  for (const auto& kv : node_) {
    if (!kv.first.IsScalar()) {
      // `null:` and `~:` read as YAML's null, not as a name, and a flow list
      // or mapping can be a key too; say which line, and how to mean a name.
      const std::string what = kv.first.IsNull()       ? "null (write \"null\" for a key of that name)"
                               : kv.first.IsSequence() ? "a list"
                                                       : "a mapping";
      throw InputError(
          Where(), "line " + std::to_string(kv.first.Mark().line + 1) + ": a key must be a plain name, not " + what);
    }
    if (!keys.insert(kv.first.Scalar()).second)
      throw InputError(Where(kv.first.Scalar()), "given twice in one mapping: keep one");
  }
}

std::string YamlMap::Where(const std::string& key) const {
  std::string path = key_path_;
  if (!key.empty()) path = path.empty() ? key : path + "." + key;
  return path.empty() ? file_ : file_ + ": " + path;
}

bool YamlMap::Has(const std::string& key) const { return static_cast<bool>(node_[key]); }

std::vector<std::string> YamlMap::Keys() const {
  std::vector<std::string> keys;
  for (const auto& kv : node_) keys.push_back(kv.first.as<std::string>());
  return keys;
}

namespace {

// The optimal string alignment distance of `a` and `b`, letter case aside:
// the insertions, deletions, substitutions and swaps of two neighbours that
// make one the other (a typed key's usual slips).
size_t TypingDistance(const std::string& a, const std::string& b) {
  auto same = [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  };
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i)
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
      if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1]))
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// Keys that differ in one axis letter or one digit, in the same place
// (corners_x / corners_y, fx / fy, cam0 / cam1): siblings a reader reads
// both of, not one misspelt as the other (corners_y named as a typo for a
// missing corners_x sent the user to rename the right one).
bool SiblingKeys(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  auto axis = [](char c) { return c == 'x' || c == 'y' || c == 'z'; };
  auto digit = [](char c) { return c >= '0' && c <= '9'; };
  int differ = 0;
  bool siblings = true;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == b[i]) continue;
    ++differ;
    siblings = (axis(a[i]) && axis(b[i])) || (digit(a[i]) && digit(b[i]));
  }
  return differ == 1 && siblings;
}

}  // namespace

std::string YamlMap::MisspeltAs(const std::string& key) const {
  // One slip in a short key, up to one in four letters in a long one
  // (right_from_lef for right_from_left: 1 of 15).
  const size_t most = std::max<size_t>(1, key.size() / 4);
  std::string closest;
  size_t closest_distance = most + 1;
  for (const auto& kv : node_) {
    const std::string& other = kv.first.Scalar();
    if (read_.count(other) || SiblingKeys(key, other)) continue;
    const size_t d = TypingDistance(key, other);
    if (d < closest_distance) {
      closest = other;
      closest_distance = d;
    }
  }
  return closest;
}

YAML::Node YamlMap::Require(const std::string& key) {
  read_.insert(key);
  YAML::Node n = node_[key];
  if (!n) {
    // A misspelt key is missing under its right name; its own name, which
    // Finish() would call unknown, is never reached. Only a key near the
    // missing one is named: one not read yet may be a key read later.
    const std::string typo = MisspeltAs(key);
    throw InputError(Where(key),
                     typo.empty() ? "missing key" : "missing key (this map has " + typo + " instead: a typo?)");
  }
  return n;
}

namespace {

// A scalar written in quotes ("2", '11'): YAML's string, whatever it
// holds. yaml-cpp converts one to a number on request all the same; the
// readers do not, as the docs promise a wrong type is an error (a quoted
// number is a string in every other YAML reader). yaml-cpp tags a quoted
// scalar "!", a plain one "?".
bool IsQuoted(const YAML::Node& n) { return n.Tag() == "!"; }

}  // namespace

double YamlMap::ToDouble(const YAML::Node& n, const std::string& where) {
  if (!n.IsScalar()) throw InputError(where, "expected a number");
  if (IsQuoted(n))
    throw InputError(where, "expected a number, got the string \"" + n.Scalar() + "\" (drop the quotes)");
  double v;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(where, "expected a number, got '" + n.Scalar() + "'");
  }
  if (!std::isfinite(v)) throw InputError(where, "NaN or Inf is not allowed");
  return v;
}

Eigen::Matrix4d YamlMap::ToMatrix4(const YAML::Node& n, const std::string& where) {
  if (!n.IsSequence() || n.size() != 4) throw InputError(where, "expected a 4x4 matrix (4 rows of 4 numbers)");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    if (!n[r].IsSequence() || n[r].size() != 4) {
      throw InputError(where, "expected a 4x4 matrix (4 rows of 4 numbers)");
    }
    for (int c = 0; c < 4; ++c) m(r, c) = ToDouble(n[r][c], where);
  }
  return m;
}

double YamlMap::GetDouble(const std::string& key) { return ToDouble(Require(key), Where(key)); }
double YamlMap::GetDouble(const std::string& key, double default_value) {
  return Has(key) ? GetDouble(key) : (read_.insert(key), default_value);
}

int YamlMap::GetInt(const std::string& key) {
  YAML::Node n = Require(key);
  if (n.IsScalar() && IsQuoted(n))
    throw InputError(Where(key), "expected an integer, got the string \"" + n.Scalar() + "\" (drop the quotes)");
  try {
    if (n.IsScalar()) return n.as<int>();
  } catch (const YAML::Exception&) {
  }
  throw InputError(Where(key), "expected an integer");
}
int YamlMap::GetInt(const std::string& key, int default_value) {
  return Has(key) ? GetInt(key) : (read_.insert(key), default_value);
}

bool YamlMap::GetBool(const std::string& key, bool default_value) {
  if (!Has(key)) {
    read_.insert(key);
    return default_value;
  }
  return GetBool(key);
}

// YAML 1.2's booleans only (true, false, and their True / TRUE forms):
// yaml-cpp also takes YAML 1.1's yes/no/on/off/y/n, which YAML 1.2 readers
// (Python's ruamel, Go's yaml.v3) read as strings: a file must mean the same
// to every reader, and the docs say `true` or `false`.
bool YamlMap::GetBool(const std::string& key) {
  YAML::Node n = Require(key);
  if (n.IsScalar() && !IsQuoted(n)) {
    const std::string& v = n.Scalar();
    if (v == "true" || v == "True" || v == "TRUE") return true;
    if (v == "false" || v == "False" || v == "FALSE") return false;
  }
  throw InputError(Where(key),
                   "expected true or false" + (n.IsScalar() ? ", got '" + n.Scalar() + "'" : std::string()));
}

std::string YamlMap::GetString(const std::string& key) {
  YAML::Node n = Require(key);
  if (!n.IsScalar()) throw InputError(Where(key), "expected a string");
  return n.Scalar();
}
std::string YamlMap::GetString(const std::string& key, const std::string& default_value) {
  return Has(key) ? GetString(key) : (read_.insert(key), default_value);
}

std::vector<double> YamlMap::GetDoubles(const std::string& key, int expected_size) {
  YAML::Node n = Require(key);
  if (!n.IsSequence()) throw InputError(Where(key), "expected a list of numbers");
  if (expected_size >= 0 && static_cast<int>(n.size()) != expected_size) {
    throw InputError(Where(key),
                     "expected " + std::to_string(expected_size) + " numbers, got " + std::to_string(n.size()));
  }
  std::vector<double> out;
  for (const auto& x : n) out.push_back(ToDouble(x, Where(key)));
  return out;
}

std::vector<int> YamlMap::GetInts(const std::string& key, int expected_size) {
  YAML::Node n = Require(key);
  if (!n.IsSequence()) throw InputError(Where(key), "expected a list of integers");
  if (expected_size >= 0 && static_cast<int>(n.size()) != expected_size) {
    throw InputError(Where(key),
                     "expected " + std::to_string(expected_size) + " integers, got " + std::to_string(n.size()));
  }
  std::vector<int> out;
  for (const auto& x : n) {
    if (x.IsScalar() && IsQuoted(x))
      throw InputError(Where(key), "expected integers, got the string \"" + x.Scalar() + "\" (drop the quotes)");
    try {
      out.push_back(x.as<int>());
    } catch (const YAML::Exception&) {
      throw InputError(Where(key), "expected integers");
    }
  }
  return out;
}

Eigen::Matrix4d YamlMap::GetMatrix4(const std::string& key) { return ToMatrix4(Require(key), Where(key)); }

YamlMap YamlMap::GetMap(const std::string& key) {
  YAML::Node n = Require(key);
  if (!n.IsMap()) throw InputError(Where(key), "expected a mapping");
  return YamlMap(n, file_, key_path_.empty() ? key : key_path_ + "." + key);
}

YamlMap YamlMap::GetMapOrEmpty(const std::string& key) {
  if (Has(key) && Require(key).IsNull())
    return YamlMap(YAML::Node(YAML::NodeType::Map), file_, key_path_.empty() ? key : key_path_ + "." + key);
  return GetMap(key);
}

std::vector<YamlMap> YamlMap::GetMaps(const std::string& key) {
  YAML::Node n = Require(key);
  if (!n.IsSequence()) throw InputError(Where(key), "expected a list");
  std::vector<YamlMap> out;
  for (size_t i = 0; i < n.size(); ++i) {
    const std::string path = (key_path_.empty() ? key : key_path_ + "." + key) + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) throw InputError(file_ + ": " + path, "expected a mapping");
    out.emplace_back(n[i], file_, path);
  }
  return out;
}

YAML::Node YamlMap::GetNode(const std::string& key) { return Require(key); }

void YamlMap::Finish() const {
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (!read_.count(key)) throw InputError(Where(key), "unknown key");
  }
}

}  // namespace stereorig
