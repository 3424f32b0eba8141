#include "rig_file.h"

#include <cstdio>
#include <ctime>
#include <map>
#include <sstream>

#include "atomic_file.h"
#include "input_error.h"
#include "lens_plausibility.h"
#include "lensmodel_config.h"
#include "number_text.h"
#include "typed_pose.h"
#include "yaml_reader.h"

namespace stereorig {

namespace {

// A YAML double-quoted scalar: safe for any text in provenance.
std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string Matrix4ToYaml(const Eigen::Matrix4d& m) {
  std::string s = "[";
  for (int r = 0; r < 4; ++r) {
    s += r ? ", [" : "[";
    for (int c = 0; c < 4; ++c) s += (c ? ", " : "") + FormatDouble(m(r, c));
    s += "]";
  }
  return s + "]";
}

Pose ReadRigidPose(const YAML::Node& n, const std::string& where) {
  return TypedRigidPose(YamlMap::ToMatrix4(n, where), where);
}

// The least distance, mm, between the centres of two cameras of a rig: a
// module's baseline, and two modules' reference cameras (S). Two camera
// bodies stand further apart; stereo modules have baselines of tens of mm.
// A distance under it is a translation typed in metres (a 90 mm baseline as
// 0.09), which the rig file read as a module of sub-millimetre baseline
// (stereorig rig: "baseline 0.0900 mm", exit 0), or none at all.
constexpr double kMinCameraSpacingMm = 1.0;

// Records `name` as list[index]'s in *named (name -> index); throws
// InputError at `where` if an earlier entry of `list` ("cameras",
// "modules") has it: the check and every report tell them apart by name.
void RequireNameOfItsOwn(std::map<std::string, int>* named, const std::string& name, int index, const std::string& list,
                         const std::string& where) {
  if (const auto [it, added] = named->emplace(name, index); !added)
    throw InputError(where, name + " is used twice (" + list + "[" + std::to_string(it->second) + "] too): each " +
                                list.substr(0, list.size() - 1) + " needs a name of its own");
}

// Throws InputError at `where` if `pose`'s translation, two camera centres'
// distance, is under kMinCameraSpacingMm; the message says it as
// `before` distance `after` ("baseline ", " mm").
void CheckCameraSpacing(const Pose& pose, const std::string& before, const std::string& after,
                        const std::string& where) {
  const double distance_mm = pose.DistanceMm();
  if (distance_mm >= kMinCameraSpacingMm) return;
  std::string why = before + NumberText(distance_mm) + after + ", under the " + NumberText(kMinCameraSpacingMm) +
                    " mm two cameras' centres stand apart at the least";
  why += distance_mm > 0 ? "; is it in metres? the unit is mm" : ": they share one centre";
  throw InputError(where, why);
}

// provenance.residuals and .uncertainties: RMS values and standard
// deviations, each >= 0. The check squares them into its thresholds: a
// negative one (-1 px) read as a large one, a threshold no night could
// fail.
std::map<std::string, double> ReadNonNegativeNumberMap(YamlMap map) {
  std::map<std::string, double> out;
  for (const std::string& key : map.Keys()) {
    out[key] = map.GetDouble(key);
    if (!(out[key] >= 0)) throw InputError(map.Where(key), "must be >= 0, got " + NumberText(out[key], 6));
  }
  return out;
}

CalibrationTarget ReadCalibrationTarget(YamlMap t) {
  CalibrationTarget out;
  out.file = t.GetString("file");
  out.corners_x = t.GetInt("corners_x");
  out.corners_y = t.GetInt("corners_y");
  for (const auto& [key, n] : {std::pair{"corners_x", out.corners_x}, std::pair{"corners_y", out.corners_y}})
    if (n < 2) throw InputError(t.Where(key), "must be at least 2 inner corners, got " + std::to_string(n));
  out.square_size_mm = t.GetDouble("square_size_mm");
  if (!(out.square_size_mm > 0))
    throw InputError(t.Where("square_size_mm"), "must be positive, got " + NumberText(out.square_size_mm, 6));
  out.double_sided = t.GetBool("double_sided");
  out.back_from_front = ReadRigidPose(t.GetNode("back_from_front"), t.Where("back_from_front"));
  out.back_from_front_file = ReadRigidPose(t.GetNode("back_from_front_file"), t.Where("back_from_front_file"));
  const std::vector<double> sigma = t.GetDoubles("back_from_front_sigma_file", 6);
  for (int k = 0; k < 6; ++k) {
    if (!(sigma[k] >= 0))
      throw InputError(t.Where("back_from_front_sigma_file"), "must be >= 0, got " + NumberText(sigma[k], 6));
    out.back_from_front_sigma_file(k) = sigma[k];
  }
  t.Finish();
  return out;
}

Rig ParseRig(YamlMap root) {
  const std::string format = root.GetString("format");
  if (format != "stereorig-rig")
    throw InputError(root.Where("format"), "expected 'stereorig-rig', got '" + format + "'");
  const int version = root.GetInt("version");
  if (version < 1 || version > kRigFileVersion) {
    throw InputError(root.Where("version"), "unsupported version " + std::to_string(version) +
                                                " (this build reads versions 1 to " + std::to_string(kRigFileVersion) +
                                                ")");
  }
  const std::string units = root.GetString("units");
  if (units != "mm") throw InputError(root.Where("units"), "expected 'mm', got '" + units + "'");

  Provenance prov;
  {
    YamlMap p = root.GetMap("provenance");
    prov.tool = p.GetString("tool");
    prov.date_utc = p.GetString("date_utc");
    prov.input = p.GetString("input");
    prov.residuals = ReadNonNegativeNumberMap(p.GetMap("residuals"));
    prov.uncertainties = ReadNonNegativeNumberMap(p.GetMap("uncertainties"));
    if (p.Has("target")) {
      if (version < 2)
        throw InputError(p.Where("target"), "is not in a version 1 rig file (version 2 added it): set version: 2");
      prov.target = ReadCalibrationTarget(p.GetMap("target"));
    }
    p.Finish();
  }

  std::vector<Camera> cameras;
  std::vector<std::string> names;
  std::map<std::string, int> camera_named;  // camera name -> its index
  for (YamlMap c : root.GetMaps("cameras")) {
    names.push_back(c.GetString("name"));
    // As a module's (below): the check names the camera that moved by it,
    // and two of one name were read, exit 0.
    RequireNameOfItsOwn(&camera_named, names.back(), static_cast<int>(cameras.size()), "cameras", c.Where("name"));
    const std::string model = c.GetString("lensmodel");
    // The Camera refuses it too; here the message names the key.
    if (const std::string p = LensmodelConfigProblem(model); !p.empty()) throw InputError(c.Where("lensmodel"), p);
    std::vector<double> intrinsics = c.GetDoubles("intrinsics");
    const std::vector<int> size = c.GetInts("imagersize", 2);
    cameras.emplace_back(model, std::move(intrinsics), size[0], size[1], c.Where());
    CheckLensIsPlausible(cameras.back(), c.Where());
    c.Finish();
  }

  std::vector<StereoModule> modules;
  std::map<std::string, int> module_named;  // module name -> its index
  for (YamlMap m : root.GetMaps("modules")) {
    StereoModule mod;
    mod.name = m.GetString("name");
    // As a layout file's (calib/layout_file.h): the name tells modules
    // apart in every report.
    RequireNameOfItsOwn(&module_named, mod.name, static_cast<int>(modules.size()), "modules", m.Where("name"));
    mod.left_camera = m.GetInt("left");
    mod.right_camera = m.GetInt("right");
    mod.right_from_left = ReadRigidPose(m.GetNode("right_from_left"), m.Where("right_from_left"));
    CheckCameraSpacing(mod.right_from_left, "baseline ", " mm", m.Where("right_from_left"));
    m.Finish();
    modules.push_back(mod);
  }

  const YAML::Node s = root.GetNode("S");
  const std::string where_s = root.Where("S");
  if (!s.IsSequence()) throw InputError(where_s, "expected M rows of M 4x4 matrices");
  std::vector<std::vector<Pose>> S;
  for (size_t i = 0; i < s.size(); ++i) {
    if (!s[i].IsSequence()) throw InputError(where_s, "expected M rows of M 4x4 matrices");
    S.emplace_back();
    for (size_t j = 0; j < s[i].size(); ++j) {
      const std::string where_ij = where_s + "[" + std::to_string(i) + "][" + std::to_string(j) + "]";
      S.back().push_back(ReadRigidPose(s[i][j], where_ij));
      if (i != j)
        CheckCameraSpacing(S.back().back(), "modules " + std::to_string(i) + " and " + std::to_string(j) + " stand ",
                           " mm apart", where_ij);
    }
  }
  root.Finish();
  Rig rig(std::move(cameras), std::move(names), std::move(modules), std::move(S), root.file());
  rig.provenance() = prov;
  return rig;
}

}  // namespace

std::string FormatDouble(double x) { return ShortestNumberText(x); }

std::string NowUtcIso8601() {
  const std::time_t t = std::time(nullptr);
  std::tm tm;
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string ToolVersion() { return std::string("stereorig ") + STEREORIG_VERSION; }

Rig ReadRigFile(const std::string& path, std::string* bytes_read) {
  return ParseRig(YamlMap::LoadFile(path, bytes_read));
}

Rig ParseRigYaml(const std::string& text, const std::string& where) {
  return ParseRig(YamlMap::LoadString(text, where));
}

std::string RigToYaml(const Rig& rig) {
  std::ostringstream o;
  const Provenance& p = rig.provenance();
  o << "# stereorig rig file: cameras, stereo modules and the S matrix.\n"
    << "# Units: mm. Format: docs/formats.md. S[i][j] = module_i_from_module_j.\n"
    << "format: stereorig-rig\n"
    << "version: " << kRigFileVersion << "\n"
    << "units: mm\n"
    << "provenance:\n"
    << "  tool: " << Quote(p.tool) << "\n"
    << "  date_utc: " << Quote(p.date_utc) << "\n"
    << "  input: " << Quote(p.input) << "\n";
  for (const auto* section : {&p.residuals, &p.uncertainties}) {
    o << (section == &p.residuals ? "  residuals:" : "  uncertainties:");
    if (section->empty()) o << " {}";
    o << "\n";
    for (const auto& [k, v] : *section) o << "    " << Quote(k) << ": " << FormatDouble(v) << "\n";
  }
  if (p.target) {
    const CalibrationTarget& t = *p.target;
    o << "  target:  # the board calibrated with; stereorig check measures with it\n"
      << "    file: " << Quote(t.file) << "\n"
      << "    corners_x: " << t.corners_x << "\n"
      << "    corners_y: " << t.corners_y << "\n"
      << "    square_size_mm: " << FormatDouble(t.square_size_mm) << "\n"
      << "    double_sided: " << (t.double_sided ? "true" : "false") << "\n"
      << "    back_from_front: " << Matrix4ToYaml(t.back_from_front.ToMatrix4()) << "  # as calibrated (stage 3)\n"
      << "    back_from_front_file: " << Matrix4ToYaml(t.back_from_front_file.ToMatrix4())
      << "  # as the target file gave it\n"
      << "    back_from_front_sigma_file: [";
    for (int k = 0; k < 6; ++k) o << (k ? ", " : "") << FormatDouble(t.back_from_front_sigma_file(k));
    o << "]  # its 1-sigma: rx, ry, rz (deg), tx, ty, tz (mm)\n";
  }
  o << "cameras:\n";
  for (int i = 0; i < rig.num_cameras(); ++i) {
    const Camera& c = rig.camera(i);
    o << "  - name: " << Quote(rig.camera_names()[i]) << "\n"
      << "    lensmodel: " << Quote(c.lensmodel_name()) << "\n"
      << "    intrinsics: [";
    for (size_t k = 0; k < c.intrinsics().size(); ++k) o << (k ? ", " : "") << FormatDouble(c.intrinsics()[k]);
    o << "]\n"
      << "    imagersize: [" << c.imager_width_px() << ", " << c.imager_height_px() << "]\n";
  }
  o << "modules:\n";
  for (const StereoModule& m : rig.modules()) {
    o << "  - name: " << Quote(m.name) << "\n"
      << "    left: " << m.left_camera << "\n"
      << "    right: " << m.right_camera << "\n"
      << "    right_from_left: " << Matrix4ToYaml(m.right_from_left.ToMatrix4()) << "\n";
  }
  o << "S:\n";
  for (int i = 0; i < rig.num_modules(); ++i) {
    o << "  -\n";
    for (int j = 0; j < rig.num_modules(); ++j) {
      o << "    - " << Matrix4ToYaml(rig.S(i, j).ToMatrix4()) << "  # module" << i << "_from_module" << j << "\n";
    }
  }
  return o.str();
}

void WriteRigFile(const Rig& rig, const std::string& path) { WriteFileAtomically(path, RigToYaml(rig)); }

}  // namespace stereorig
