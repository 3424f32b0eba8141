#include "apps/tuned_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>

#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"

namespace stereorig {

std::string TunedOptionsYaml(const std::string& base_path, const std::vector<GridPeriodKey>& keys,
                             const std::string& header) {
  YAML::Node root = base_path.empty() ? YAML::Node(YAML::NodeType::Map) : YAML::LoadFile(base_path);
  if (!root.IsMap()) root = YAML::Node(YAML::NodeType::Map);  // an empty file: every key at its default
  if (!root["match"].IsMap()) root["match"] = YAML::Node(YAML::NodeType::Map);
  YAML::Node match = root["match"];
  for (const GridPeriodKey& k : keys) {
    if (k.value == std::round(k.value))
      match[k.key] = long(k.value);
    else
      match[k.key] = k.value;
  }
  YAML::Emitter out;
  out << root;
  std::ostringstream text;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);) text << "# " << line << "\n";
  text << out.c_str() << "\n";
  return text.str();
}

void CheckOptionsPath(const std::string& path) {
  if (!EndsWithIgnoringCase(path, ".yaml") && !EndsWithIgnoringCase(path, ".yml"))
    throw InputError(path, "an options file must end in .yaml or .yml");
}

}  // namespace stereorig
