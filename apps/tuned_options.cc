#include "apps/tuned_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>

#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"

namespace stereorig {

std::string TunedOptionsYaml(const std::string& base_text, const std::vector<GridPeriodKey>& keys,
                             const std::string& header) {
  // Parsed and checked before (ParseRuntimeOptions): valid YAML, a mapping
  // or an empty document (every key at its default).
  YAML::Node root = YAML::Load(base_text);
  if (!root.IsMap()) root = YAML::Node(YAML::NodeType::Map);
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
