#include "targets/target_file.h"

#include <sstream>
#include <utility>

#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "calib/core/typed_pose.h"
#include "calib/core/yaml_reader.h"

namespace stereorig {

namespace {

Target ParseTarget(YamlMap root) {
  const std::string format = root.GetString("format");
  if (format != "stereorig-target") throw InputError(root.Where("format"), "expected 'stereorig-target'");
  if (root.GetInt("version") != 1) throw InputError(root.Where("version"), "unsupported version (this build reads 1)");
  if (root.GetString("units") != "mm") throw InputError(root.Where("units"), "expected 'mm'");
  Target::Layout l;
  l.corners_x = root.GetInt("corners_x");
  l.corners_y = root.GetInt("corners_y");
  for (const auto& [key, n] : {std::pair{"corners_x", l.corners_x}, std::pair{"corners_y", l.corners_y}})
    if (n > kMaxInnerCorners)
      throw InputError(root.Where(key), std::to_string(n) + ": more than " + std::to_string(kMaxInnerCorners) +
                                            ", the most inner corners a side (as `stereorig target --corners`): " +
                                            std::to_string(kMaxInnerCorners) +
                                            " squares across a 752 px imager leave under 4 px each");
  l.square_size_mm = root.GetDouble("square_size_mm");
  l.double_sided = root.GetBool("double_sided", true);
  l.margin_mm = root.GetDouble("margin_mm", l.double_sided ? l.margin_mm : l.square_size_mm);
  l.flatness_allowance_mm = root.GetDouble("flatness_allowance_mm", 0.0);
  if (l.double_sided) {
    l.tag_family = root.GetString("tag_family");
    l.tag_size_mm = root.GetDouble("tag_size_mm");
    for (int f = 0; f < 2; ++f) {
      for (YamlMap t : root.GetMaps(f == 0 ? "front_tags" : "back_tags")) {
        const std::vector<double> c = t.GetDoubles("center_mm", 2);
        l.faces[f].tags.push_back({t.GetInt("id"), c[0], c[1]});
        t.Finish();
      }
    }
    l.back_from_front = TypedRigidPose(root.GetMatrix4("back_from_front"), root.Where("back_from_front"));
    const std::vector<double> sigma = root.GetDoubles("back_from_front_sigma", 6);
    for (int i = 0; i < 6; ++i) {
      if (sigma[i] < 0) throw InputError(root.Where("back_from_front_sigma"), "must not be negative");
      l.back_from_front_sigma[i] = sigma[i];
    }
  }
  root.Finish();
  return Target(l, root.file());
}

}  // namespace

Target ReadTargetFile(const std::string& path) { return ParseTarget(YamlMap::LoadFile(path)); }
Target ParseTargetYaml(const std::string& text, const std::string& where) {
  return ParseTarget(YamlMap::LoadString(text, where));
}

std::string TargetToYaml(const Target& target) {
  const Target::Layout& l = target.layout();
  std::ostringstream o;
  o << "# stereorig target file. Units: mm. Format: docs/formats.md.\n"
    << "# Face frame: origin at inner corner 0, x along a row, y down a column, z into the board.\n"
    << "format: stereorig-target\nversion: 1\nunits: mm\n"
    << "corners_x: " << l.corners_x << "        # inner corners along a row\n"
    << "corners_y: " << l.corners_y << "        # inner corners along a column\n"
    << "square_size_mm: " << FormatDouble(l.square_size_mm) << "\n"
    << "double_sided: " << (l.double_sided ? "true" : "false") << "\n"
    << "margin_mm: " << FormatDouble(l.margin_mm) << "\n"
    << "flatness_allowance_mm: " << FormatDouble(l.flatness_allowance_mm) << "\n";
  if (l.double_sided) {
    o << "tag_family: " << l.tag_family << "\n"
      << "tag_size_mm: " << FormatDouble(l.tag_size_mm) << "   # edge of the black border square\n";
    for (int f = 0; f < 2; ++f) {
      o << (f == 0 ? "front_tags:\n" : "back_tags:\n");
      for (const TagPlacement& t : l.faces[f].tags) {
        o << "  - {id: " << t.id << ", center_mm: [" << FormatDouble(t.center_x_mm) << ", "
          << FormatDouble(t.center_y_mm) << "]}\n";
      }
    }
    const Eigen::Matrix4d m = l.back_from_front.ToMatrix4();
    o << "back_from_front: [";
    for (int r = 0; r < 4; ++r) {
      o << (r ? ", [" : "[");
      for (int c = 0; c < 4; ++c) o << (c ? ", " : "") << FormatDouble(m(r, c));
      o << "]";
    }
    o << "]\n# 1-sigma of back_from_front: rx, ry, rz (deg), tx, ty, tz (mm)\nback_from_front_sigma: [";
    for (int i = 0; i < 6; ++i) o << (i ? ", " : "") << FormatDouble(l.back_from_front_sigma[i]);
    o << "]\n";
  }
  return o.str();
}

void WriteTargetFile(const Target& target, const std::string& path) { WriteFileAtomically(path, TargetToYaml(target)); }

}  // namespace stereorig
