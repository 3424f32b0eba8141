#include "calib/layout_file.h"

#include <algorithm>
#include <map>
#include <string>

#include "calib/core/input_error.h"
#include "calib/core/yaml_reader.h"

namespace stereorig {

namespace {

std::vector<ModuleLayout> Parse(YamlMap root) {
  std::vector<ModuleLayout> out;
  std::map<int, std::string> module_of_camera;  // camera index -> the module naming it
  std::map<std::string, int> module_named;      // module name -> its index
  for (YamlMap m : root.GetMaps("modules")) {
    ModuleLayout l;
    l.name = m.GetString("name");
    // An empty name tells no module apart (the rig file's modules, the
    // report's module_stereo_rms_px), and was accepted.
    if (l.name.empty()) throw InputError(m.Where("name"), "is empty: each module needs a name of its own");
    // The name tells modules apart in the rig file and in every report
    // (module0_stereo_rms_px): two of one name wrote a rig of two
    // "module0", exit 0.
    if (const auto [it, added] = module_named.emplace(l.name, static_cast<int>(out.size())); !added)
      throw InputError(m.Where("name"), l.name + " is used twice (modules[" + std::to_string(it->second) +
                                            "] too): each module needs a name of its own");
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
    // Refused here, when the file is read, rather than after every image of
    // the captures has been detected (calibrate's input checks).
    for (const int c : {l.left_camera, l.right_camera}) {
      const auto [it, added] = module_of_camera.emplace(c, l.name);
      if (!added)
        throw InputError(m.Where(), "camera " + std::to_string(c) + " is already in module " + it->second +
                                        ": each camera belongs to exactly one module");
    }
    m.Finish();
    out.push_back(l);
  }
  if (out.empty()) throw InputError(root.Where("modules"), "no modules");
  // Cameras are numbered 0..N-1 (camK.png in each capture): one left out of
  // every module is a gap.
  for (int c = 0, n = module_of_camera.rbegin()->first + 1; c < n; ++c)
    if (!module_of_camera.count(c))
      throw InputError(root.Where("modules"), "camera " + std::to_string(c) + " is in no module, though camera " +
                                                  std::to_string(n - 1) +
                                                  " is: cameras are numbered 0.. without gaps, each in one module");
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
