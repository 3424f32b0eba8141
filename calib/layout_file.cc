#include "calib/layout_file.h"

#include <algorithm>

#include "calib/core/input_error.h"
#include "calib/core/yaml_reader.h"

namespace stereorig {

namespace {

std::vector<ModuleLayout> Parse(YamlMap root) {
  std::vector<ModuleLayout> out;
  for (YamlMap m : root.GetMaps("modules")) {
    ModuleLayout l;
    l.name = m.GetString("name");
    l.left_camera = m.GetInt("left");
    l.right_camera = m.GetInt("right");
    if (m.Has("face")) {
      const std::string f = m.GetString("face");
      if (f == "front") {
        l.face = Face::kFront;
      } else if (f == "back") {
        l.face = Face::kBack;
      } else {
        throw InputError(m.Where("face"), "must be 'front' or 'back', got '" + f + "'");
      }
    }
    if (l.left_camera < 0 || l.right_camera < 0 || l.left_camera == l.right_camera) {
      throw InputError(m.Where(), "left and right must be two different camera indices >= 0");
    }
    m.Finish();
    out.push_back(l);
  }
  if (out.empty()) throw InputError(root.Where("modules"), "no modules");
  root.Finish();
  return out;
}

}  // namespace

std::vector<ModuleLayout> ReadLayoutFile(const std::string& path) { return Parse(YamlMap::LoadFile(path)); }

int LayoutCameraCount(const std::vector<ModuleLayout>& modules) {
  int n = 0;
  for (const ModuleLayout& m : modules) n = std::max({n, m.left_camera + 1, m.right_camera + 1});
  return n;
}

std::vector<ModuleLayout> ParseLayoutYaml(const std::string& text, const std::string& where) {
  return Parse(YamlMap::LoadString(text, where));
}

}  // namespace stereorig
