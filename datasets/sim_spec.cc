#include "datasets/sim_spec.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "calib/core/camera.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/lens_plausibility.h"
#include "calib/core/lensmodel_config.h"
#include "calib/core/number_text.h"
#include "calib/core/rig_file.h"
#include "calib/core/yaml_reader.h"

namespace stereorig {

namespace {

namespace fs = std::filesystem;

constexpr double kDegToRad = M_PI / 180.0;

void Require(bool ok, const std::string& where, const std::string& key, const std::string& problem) {
  if (!ok) throw InputError(where + (key.empty() ? "" : ": " + key), problem);
}

// The spec file is for editing: 0.6, not %.17g's 0.59999999999999998, and
// still the same double read back.
std::string Num(double x) { return ShortestNumberText(x); }

std::string Vec(const Eigen::Vector3d& v) {
  std::ostringstream o;
  o << '[' << Num(v.x()) << ", " << Num(v.y()) << ", " << Num(v.z()) << ']';
  return o.str();
}

Eigen::Vector3d GetVec3(YamlMap& m, const std::string& key, const Eigen::Vector3d& def) {
  if (!m.Has(key)) {
    m.GetDouble(key, 0.0);  // marks the key as read
    return def;
  }
  const std::vector<double> v = m.GetDoubles(key, 3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

CameraSpec ParseCamera(YamlMap m) {
  CameraSpec c;
  c.lensmodel = m.GetString("lensmodel");
  // The Camera below refuses it too; here the message names the key.
  if (const std::string p = LensmodelConfigProblem(c.lensmodel); !p.empty()) throw InputError(m.Where("lensmodel"), p);
  c.intrinsics = m.GetDoubles("intrinsics");
  const std::vector<int> size = m.GetInts("imager_size", 2);
  c.width_px = size[0];
  c.height_px = size[1];
  m.Finish();
  // Validates the model name and the number of intrinsics, then that it
  // could be a real lens (as a rig file's cameras are), naming the key.
  CheckLensIsPlausible(Camera(c.lensmodel, c.intrinsics, c.width_px, c.height_px, m.Where()), m.Where());
  return c;
}

ProjectorSpec ParseProjector(YamlMap m) {
  ProjectorSpec p;
  m.Read("enabled", &p.enabled);
  p.offset_mm = GetVec3(m, "offset_mm", p.offset_mm);
  m.Read("lines", &p.lines);
  m.Read("fan_angle_deg", &p.fan_angle_deg);
  m.Read("rotation_deg", &p.rotation_deg);
  m.Read("line_sigma_mrad", &p.line_sigma_mrad);
  m.Read("power_dn", &p.power_dn);
  m.Finish();
  Require(p.lines >= 2, m.Where(), "lines", "must be at least 2");
  Require(p.fan_angle_deg > 0 && p.fan_angle_deg < 170, m.Where(), "fan_angle_deg", "must be in (0, 170)");
  Require(p.line_sigma_mrad > 0, m.Where(), "line_sigma_mrad", "must be positive");
  // Neighbouring lines closer than 2 sigma merge: their sum ripples by under
  // 3 % of its mean, peak to trough (4 exp(-pi^2 / 2) at 2 sigma), nearly
  // even light with no grid to match or score. 51
  // lines over the default 23 deg fan stand 8 sigma apart; the bound is 200
  // there. (lines: 1000000000 was accepted and rendered as such.)
  // (Direction cosines, mrad: the units of line_sigma_mrad in render.h.)
  const double fan_span_mrad = 2e3 * std::sin(0.5 * p.fan_angle_deg * M_PI / 180.0);
  const double spacing_mrad = fan_span_mrad / (p.lines - 1);
  if (!(spacing_mrad >= 2 * p.line_sigma_mrad)) {
    // Only here: a line_sigma_mrad of 1e-300 would overflow the int.
    const int most_lines = 1 + static_cast<int>(std::floor(fan_span_mrad / (2 * p.line_sigma_mrad)));
    Require(false, m.Where(), "lines",
            std::to_string(p.lines) + " lines over the fan stand " + NumberText(spacing_mrad, 3) +
                " mrad apart, under 2 line_sigma_mrad (" + Num(2 * p.line_sigma_mrad) +
                "): they merge into even light; at most " + std::to_string(most_lines) +
                " with this fan_angle_deg and line_sigma_mrad");
  }
  Require(p.power_dn >= 0, m.Where(), "power_dn", "must not be negative");
  return p;
}

ModuleSpec ParseModule(YamlMap m) {
  ModuleSpec s;
  s.name = m.GetString("name");
  s.center_mm = GetVec3(m, "center_mm", s.center_mm);
  s.look_at_mm = GetVec3(m, "look_at_mm", s.look_at_mm);
  s.up = GetVec3(m, "up", s.up);
  m.Read("baseline_mm", &s.baseline_mm);
  m.Read("verging_deg", &s.verging_deg);
  s.left = ParseCamera(m.GetMap("left_camera"));
  s.right = ParseCamera(m.GetMap("right_camera"));
  if (m.Has("projector")) {
    s.projector = ParseProjector(m.GetMap("projector"));
  } else {
    s.projector.enabled = false;
  }
  m.Finish();
  // The rig file refuses cameras closer than 1 mm (calib/core/rig_file.h): a
  // spec under it would render a dataset whose truth rig cannot be read.
  Require(s.baseline_mm >= 1, m.Where(), "baseline_mm", "must be at least 1 mm (is it in metres? the unit is mm)");
  Require(std::abs(s.verging_deg) < 90, m.Where(), "verging_deg", "must be within +-90");
  const Eigen::Vector3d z = s.look_at_mm - s.center_mm;
  Require(z.norm() > 1e-6, m.Where(), "look_at_mm", "must differ from center_mm");
  Require(z.normalized().cross(s.up).norm() > 1e-6, m.Where(), "up", "must not be parallel to the viewing direction");
  return s;
}

}  // namespace

void RenderSpec::Check(const std::string& where) const {
  Require(samples_per_axis >= 2 && samples_per_axis <= 16, where, "samples_per_axis", "must be in [2, 16]");
  Require(edge_samples_per_axis >= 2 && edge_samples_per_axis <= 32, where, "edge_samples_per_axis",
          "must be in [2, 32]");
  Require(ambient_dn >= 0, where, "ambient_dn", "must not be negative");
  Require(ambient_directional >= 0 && ambient_directional <= 1, where, "ambient_directional", "must be in [0, 1]");
  Require(background_dn >= 0, where, "background_dn", "must not be negative");
  Require(stray_light_dn >= 0, where, "stray_light_dn", "must not be negative");
  Require(psf_sigma_px >= 0 && psf_sigma_px <= 10, where, "psf_sigma_px", "must be in [0, 10]");
  Require(full_well_e > 0, where, "full_well_e", "must be positive");
  Require(read_noise_e >= 0, where, "read_noise_e", "must not be negative");
  Require(speckle_contrast >= 0 && speckle_contrast <= 1, where, "speckle_contrast", "must be in [0, 1]");
  Require(speckle_grain_px > 0, where, "speckle_grain_px", "must be positive");
  Require(texture_contrast >= 0 && texture_contrast < 0.5, where, "texture_contrast", "must be in [0, 0.5)");
  Require(texture_wavelength_mm > 0, where, "texture_wavelength_mm", "must be positive");
}

void CalibrationSpec::Check(const std::string& where) const {
  Require(captures >= 0 && captures <= 999, where, "captures", "must be in [0, 999]");
  Require(tilt_max_deg >= 0 && tilt_max_deg <= 70, where, "tilt_max_deg", "must be in [0, 70]");
  Require(roll_max_deg >= 0 && roll_max_deg <= 180, where, "roll_max_deg", "must be in [0, 180]");
  Require(volume_mm.minCoeff() >= 0, where, "volume_mm", "must not be negative");
  Require(std::abs(scale_error_ppm) < 1e5, where, "scale_error_ppm", "must be within +-1e5");
  Require(std::abs(back_misalignment_deg) < 10, where, "back_misalignment_deg", "must be within +-10");
  Require(std::abs(back_misalignment_mm) < 10, where, "back_misalignment_mm", "must be within +-10");
  Require(std::abs(nonflatness_mm) < 10, where, "nonflatness_mm", "must be within +-10");
  Require(white_albedo > black_albedo && black_albedo >= 0 && white_albedo <= 1, where, "white_albedo",
          "need 0 <= black_albedo < white_albedo <= 1");
  Require(min_corners_per_camera >= 0, where, "min_corners_per_camera", "must not be negative");
}

void ScenesSpec::Check(const std::string& where) const {
  static const std::set<std::string> known = {"cup", "sphere", "ballbar", "plate", "tuber"};
  std::set<std::string> seen;
  for (const std::string& n : names) {
    Require(known.count(n) == 1, where, "names", "unknown scene '" + n + "' (cup, sphere, ballbar, plate, tuber)");
    Require(seen.insert(n).second, where, "names", "scene '" + n + "' listed twice");
  }
  Require(wobble_shift_mm >= 0, where, "wobble_shift_mm", "must not be negative");
  Require(wobble_tilt_deg >= 0 && wobble_tilt_deg < 45, where, "wobble_tilt_deg", "must be in [0, 45)");
  Require(cup_diameter_mm > 10 && cup_height_mm > 10, where, "cup_diameter_mm", "cup must be larger than 10 mm");
  Require(sphere_diameter_mm > 0, where, "sphere_diameter_mm", "must be positive");
  Require(ballbar_sphere_diameter_mm > 0, where, "ballbar_sphere_diameter_mm", "must be positive");
  Require(plate_size_mm.minCoeff() > 0, where, "plate_size_mm", "must be positive");
  Require(tuber_semi_axes_mm.minCoeff() > 0, where, "tuber_semi_axes_mm", "must be positive");
  Require(tuber_bump >= 0 && tuber_bump < 0.3, where, "tuber_bump", "must be in [0, 0.3)");
  // The scenes are objects on the belt, their truth surface sampled every
  // 0.2 mm (SimulateOptions::surface_spacing_mm): a 300 mm cube is 1.4e7
  // points. A cup 100 m across (75 mm typed in micrometres, say) rendered
  // for minutes, then aborted in std::bad_alloc (exit 134).
  constexpr double kMaxSizeMm = 300;
  struct Extent {
    const char* key;     // the key that sets it
    const char* object;  // what is that large
    double size_mm;
  };
  const Extent extents[] = {
      {"cup_diameter_mm", "cup", cup_diameter_mm},
      {"cup_height_mm", "cup", cup_height_mm},
      {"sphere_diameter_mm", "sphere", sphere_diameter_mm},
      // One entry for the bar, named by the larger of its two keys.
      {ballbar_distance_mm >= ballbar_sphere_diameter_mm ? "ballbar_distance_mm" : "ballbar_sphere_diameter_mm",
       "ball bar (its distance plus a ball)", ballbar_distance_mm + ballbar_sphere_diameter_mm},
      {"plate_size_mm", "plate", plate_size_mm.maxCoeff()},
      {"tuber_semi_axes_mm", "tuber (its longest axis with its bumps)",
       2 * tuber_semi_axes_mm.maxCoeff() * (1 + tuber_bump)}};
  for (const Extent& e : extents)
    Require(e.size_mm <= kMaxSizeMm, where, e.key,
            std::string("the ") + e.object + " is " + ShortestNumberText(e.size_mm) + " mm across, over the " +
                ShortestNumberText(kMaxSizeMm) +
                " mm a scene on the belt may be (its truth surface is sampled every 0.2 mm); is it in "
                "micrometres? the unit is mm");
  // After the sizes: a ball typed in micrometres is named as the ball (its
  // bar over 300 mm), not as a distance short of it.
  Require(ballbar_distance_mm > ballbar_sphere_diameter_mm, where, "ballbar_distance_mm",
          "must exceed the sphere diameter");
  for (double a : {cup_albedo, artifact_albedo, tuber_albedo}) {
    Require(a > 0 && a <= 1, where, "albedo", "albedos must be in (0, 1]");
  }
}

void SimSpec::Check(const std::string& where) const {
  Require(!modules.empty(), where, "modules", "needs at least one module");
  std::set<std::string> names;
  for (size_t k = 0; k < modules.size(); ++k) {
    const ModuleSpec& m = modules[k];
    Require(names.insert(m.name).second, where, "modules", "module name '" + m.name + "' used twice");
    // The runtime matches a module's two images row by row and refuses a
    // rig whose module has two imager sizes (reconstruct/runtime.cc): a
    // dataset rendered from such a spec could never be reconstructed.
    const auto size = [](const CameraSpec& c) {
      return std::to_string(c.width_px) + "x" + std::to_string(c.height_px);
    };
    Require(m.left.width_px == m.right.width_px && m.left.height_px == m.right.height_px, where,
            "modules[" + std::to_string(k) + "]: right_camera: imager_size",
            size(m.right) + " differs from left_camera's " + size(m.left) +
                ": a module's two cameras need one imager size (window both alike)");
  }
  render.Check(where + ": render");
  calibration.Check(where + ": calibration");
  scenes.Check(where + ": scenes");
}

SimSpec DefaultSimSpec() {
  const DefaultRigGeometry g;
  const SimulatedRig rig = MakeDefaultRig(g);
  SimSpec spec;
  for (int m = 0; m < 2; ++m) {
    ModuleSpec s;
    s.name = "module" + std::to_string(m);
    s.center_mm = Eigen::Vector3d(0, 0, m == 0 ? -g.working_distance_mm : g.working_distance_mm);
    s.baseline_mm = g.baseline_mm;
    s.verging_deg = g.verging_deg;
    for (int side = 0; side < 2; ++side) {
      const Camera& c = rig.rig.camera(2 * m + side);
      CameraSpec& cs = side == 0 ? s.left : s.right;
      cs.lensmodel = c.lensmodel_name();
      cs.intrinsics = c.intrinsics();
      cs.width_px = c.imager_width_px();
      cs.height_px = c.imager_height_px();
    }
    spec.modules.push_back(s);
  }
  return spec;
}

SimSpec ParseSimSpecYaml(const std::string& text, const std::string& where) {
  YamlMap root = YamlMap::LoadString(text, where);
  Require(root.GetString("format") == "stereorig-sim-spec", root.Where("format"), "", "expected 'stereorig-sim-spec'");
  Require(root.GetInt("version") == 1, root.Where("version"), "", "unsupported version (this build reads 1)");
  Require(root.GetString("units") == "mm", root.Where("units"), "", "expected 'mm'");
  SimSpec s;
  for (YamlMap m : root.GetMaps("modules")) s.modules.push_back(ParseModule(m));
  // The truth's lit maps hold one bit per projector, 8 to a pixel
  // (render.h): a ninth would light the scenes but never the lit maps that
  // fill and the projector warnings are judged by.
  const auto projectors =
      std::count_if(s.modules.begin(), s.modules.end(), [](const ModuleSpec& m) { return m.projector.enabled; });
  Require(projectors <= 8, root.Where("modules"), "",
          std::to_string(projectors) + " modules have a projector; the truth's lit maps hold 8 (one bit each)");
  if (root.Has("render")) {
    YamlMap r = root.GetMap("render");
    RenderSpec& d = s.render;
    r.Read("samples_per_axis", &d.samples_per_axis);
    r.Read("edge_samples_per_axis", &d.edge_samples_per_axis);
    r.Read("ambient_dn", &d.ambient_dn);
    r.Read("ambient_directional", &d.ambient_directional);
    r.Read("background_dn", &d.background_dn);
    r.Read("stray_light_dn", &d.stray_light_dn);
    r.Read("psf_sigma_px", &d.psf_sigma_px);
    r.Read("noise", &d.noise);
    r.Read("full_well_e", &d.full_well_e);
    r.Read("read_noise_e", &d.read_noise_e);
    r.Read("speckle_contrast", &d.speckle_contrast);
    r.Read("speckle_grain_px", &d.speckle_grain_px);
    r.Read("texture_contrast", &d.texture_contrast);
    r.Read("texture_wavelength_mm", &d.texture_wavelength_mm);
    r.Finish();
    d.Check(r.Where());
  }
  if (root.Has("calibration")) {
    YamlMap c = root.GetMap("calibration");
    CalibrationSpec& d = s.calibration;
    c.Read("captures", &d.captures);
    d.target = c.GetString("target", d.target);
    c.Read("tilt_max_deg", &d.tilt_max_deg);
    c.Read("roll_max_deg", &d.roll_max_deg);
    d.volume_mm = GetVec3(c, "volume_mm", d.volume_mm);
    c.Read("scale_error_ppm", &d.scale_error_ppm);
    c.Read("back_misalignment_deg", &d.back_misalignment_deg);
    c.Read("back_misalignment_mm", &d.back_misalignment_mm);
    c.Read("nonflatness_mm", &d.nonflatness_mm);
    c.Read("white_albedo", &d.white_albedo);
    c.Read("black_albedo", &d.black_albedo);
    c.Read("min_corners_per_camera", &d.min_corners_per_camera);
    c.Finish();
    d.Check(c.Where());
  }
  if (root.Has("scenes")) {
    YamlMap c = root.GetMap("scenes");
    ScenesSpec& d = s.scenes;
    if (c.Has("names")) {
      d.names.clear();
      YAML::Node n = c.GetNode("names");
      Require(n.IsSequence(), c.Where("names"), "", "expected a list of scene names");
      for (const YAML::Node& e : n) {
        Require(e.IsScalar(), c.Where("names"), "", "expected a list of scene names");
        d.names.push_back(e.as<std::string>());
      }
    }
    c.Read("wobble_shift_mm", &d.wobble_shift_mm);
    c.Read("wobble_tilt_deg", &d.wobble_tilt_deg);
    c.Read("cup_diameter_mm", &d.cup_diameter_mm);
    c.Read("cup_height_mm", &d.cup_height_mm);
    c.Read("cup_albedo", &d.cup_albedo);
    c.Read("sphere_diameter_mm", &d.sphere_diameter_mm);
    c.Read("ballbar_sphere_diameter_mm", &d.ballbar_sphere_diameter_mm);
    c.Read("ballbar_distance_mm", &d.ballbar_distance_mm);
    d.plate_size_mm = GetVec3(c, "plate_size_mm", d.plate_size_mm);
    d.tuber_semi_axes_mm = GetVec3(c, "tuber_semi_axes_mm", d.tuber_semi_axes_mm);
    c.Read("tuber_bump", &d.tuber_bump);
    c.Read("artifact_albedo", &d.artifact_albedo);
    c.Read("tuber_albedo", &d.tuber_albedo);
    c.Finish();
    d.Check(c.Where());
  }
  root.Finish();
  s.Check(where);
  return s;
}

SimSpec ReadSimSpecFile(const std::string& path) {
  SimSpec spec = ParseSimSpecYaml(ReadInputText(path), path);
  // A spec and its board go together: a relative target was read from the
  // current folder, so the spec rendered only from its own folder, and a
  // missing board was reported without the key that named it.
  std::string& target = spec.calibration.target;
  if (target != "default") {
    const bool relative = fs::path(target).is_relative();
    target = (fs::path(path).parent_path() / target).string();
    std::error_code ec;
    if (!fs::is_regular_file(target, ec)) {
      throw InputError(path + ": calibration.target",
                       "no file " + target + (relative ? " (a relative target is read from the spec's folder)" : ""));
    }
  }
  return spec;
}

std::string SimSpecToYaml(const SimSpec& s) {
  std::ostringstream o;
  o << "# stereorig simulator spec (docs/simulator.md). Units: mm, degrees, DN = 8-bit grey levels.\n"
    << "# World frame: volume centred on the origin, y down (gravity), conveyor along x.\n"
    << "format: stereorig-sim-spec\nversion: 1\nunits: mm\n"
    << "modules:\n";
  auto camera = [&](const char* key, const CameraSpec& c) {
    o << "    " << key << ":\n"
      << "      lensmodel: " << c.lensmodel << "\n"
      << "      intrinsics: [";
    for (size_t i = 0; i < c.intrinsics.size(); ++i) o << (i ? ", " : "") << Num(c.intrinsics[i]);
    o << "]\n      imager_size: [" << c.width_px << ", " << c.height_px << "]\n";
  };
  for (const ModuleSpec& m : s.modules) {
    o << "  - name: " << m.name << "\n"
      << "    center_mm: " << Vec(m.center_mm) << "     # nominal centre (midway between the cameras)\n"
      << "    look_at_mm: " << Vec(m.look_at_mm) << "\n"
      << "    up: " << Vec(m.up) << "             # world direction seen as up in the images\n"
      << "    baseline_mm: " << Num(m.baseline_mm) << "\n"
      << "    verging_deg: " << Num(m.verging_deg) << "   # angle between the optical axes\n";
    camera("left_camera", m.left);
    camera("right_camera", m.right);
    const ProjectorSpec& p = m.projector;
    o << "    projector:\n"
      << "      enabled: " << (p.enabled ? "true" : "false") << "\n"
      << "      offset_mm: " << Vec(p.offset_mm) << "   # from the nominal centre, module frame\n"
      << "      lines: " << p.lines << "              # N x N grid\n"
      << "      fan_angle_deg: " << Num(p.fan_angle_deg) << "\n"
      << "      rotation_deg: " << Num(p.rotation_deg) << "     # about its axis, against the rows\n"
      << "      line_sigma_mrad: " << Num(p.line_sigma_mrad) << "    # Gaussian 1-sigma of a line\n"
      << "      power_dn: " << Num(p.power_dn) << "   # line centre, albedo 1, facing, at working distance\n";
  }
  const RenderSpec& r = s.render;
  o << "render:\n"
    << "  samples_per_axis: " << r.samples_per_axis << "        # n x n rays per pixel (scenes)\n"
    << "  edge_samples_per_axis: " << r.edge_samples_per_axis << "   # n x n on target print edges\n"
    << "  ambient_dn: " << Num(r.ambient_dn) << "\n"
    << "  ambient_directional: " << Num(r.ambient_directional) << "\n"
    << "  background_dn: " << Num(r.background_dn) << "\n"
    << "  stray_light_dn: " << Num(r.stray_light_dn) << "\n"
    << "  psf_sigma_px: " << Num(r.psf_sigma_px) << "\n"
    << "  noise: " << (r.noise ? "true" : "false") << "\n"
    << "  full_well_e: " << Num(r.full_well_e) << "\n"
    << "  read_noise_e: " << Num(r.read_noise_e) << "\n"
    << "  speckle_contrast: " << Num(r.speckle_contrast) << "\n"
    << "  speckle_grain_px: " << Num(r.speckle_grain_px) << "\n"
    << "  texture_contrast: " << Num(r.texture_contrast) << "\n"
    << "  texture_wavelength_mm: " << Num(r.texture_wavelength_mm) << "\n";
  const CalibrationSpec& c = s.calibration;
  o << "calibration:\n"
    << "  captures: " << c.captures << "\n"
    << "  target: " << c.target << "          # 'default' or a target file (a relative path: from this file's folder)\n"
    << "  tilt_max_deg: " << Num(c.tilt_max_deg) << "\n"
    << "  roll_max_deg: " << Num(c.roll_max_deg) << "\n"
    << "  volume_mm: " << Vec(c.volume_mm) << "\n"
    << "  scale_error_ppm: " << Num(c.scale_error_ppm) << "\n"
    << "  back_misalignment_deg: " << Num(c.back_misalignment_deg) << "\n"
    << "  back_misalignment_mm: " << Num(c.back_misalignment_mm) << "\n"
    << "  nonflatness_mm: " << Num(c.nonflatness_mm) << "\n"
    << "  white_albedo: " << Num(c.white_albedo) << "\n"
    << "  black_albedo: " << Num(c.black_albedo) << "\n"
    << "  min_corners_per_camera: " << c.min_corners_per_camera << "\n";
  const ScenesSpec& n = s.scenes;
  o << "scenes:\n  names: [";
  for (size_t i = 0; i < n.names.size(); ++i) o << (i ? ", " : "") << n.names[i];
  o << "]\n"
    << "  wobble_shift_mm: " << Num(n.wobble_shift_mm) << "\n"
    << "  wobble_tilt_deg: " << Num(n.wobble_tilt_deg) << "\n"
    << "  cup_diameter_mm: " << Num(n.cup_diameter_mm) << "\n"
    << "  cup_height_mm: " << Num(n.cup_height_mm) << "\n"
    << "  cup_albedo: " << Num(n.cup_albedo) << "\n"
    << "  sphere_diameter_mm: " << Num(n.sphere_diameter_mm) << "\n"
    << "  ballbar_sphere_diameter_mm: " << Num(n.ballbar_sphere_diameter_mm) << "\n"
    << "  ballbar_distance_mm: " << Num(n.ballbar_distance_mm) << "\n"
    << "  plate_size_mm: " << Vec(n.plate_size_mm) << "\n"
    << "  tuber_semi_axes_mm: " << Vec(n.tuber_semi_axes_mm) << "\n"
    << "  tuber_bump: " << Num(n.tuber_bump) << "\n"
    << "  artifact_albedo: " << Num(n.artifact_albedo) << "\n"
    << "  tuber_albedo: " << Num(n.tuber_albedo) << "\n";
  return o.str();
}

SpecRig BuildSpecRig(const SimSpec& spec) {
  spec.Check();
  std::vector<Camera> cameras;
  std::vector<std::string> names;
  std::vector<StereoModule> modules;
  std::vector<Pose> world_from_module;
  SpecRig out;
  for (size_t m = 0; m < spec.modules.size(); ++m) {
    const ModuleSpec& s = spec.modules[m];
    const Eigen::Vector3d z = (s.look_at_mm - s.center_mm).normalized();
    const Eigen::Vector3d x = z.cross(s.up).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d r;
    r << x, y, z;
    const Pose world_from_nominal(r, s.center_mm);
    const double half_verge = 0.5 * s.verging_deg * kDegToRad;
    const Pose nominal_from_left(Eigen::AngleAxisd(half_verge, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                 Eigen::Vector3d(-0.5 * s.baseline_mm, 0, 0));
    const Pose nominal_from_right(Eigen::AngleAxisd(-half_verge, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                  Eigen::Vector3d(0.5 * s.baseline_mm, 0, 0));
    const int left = static_cast<int>(cameras.size());
    const std::string where = "spec: modules[" + std::to_string(m) + "]";
    cameras.emplace_back(s.left.lensmodel, s.left.intrinsics, s.left.width_px, s.left.height_px,
                         where + ".left_camera");
    cameras.emplace_back(s.right.lensmodel, s.right.intrinsics, s.right.width_px, s.right.height_px,
                         where + ".right_camera");
    names.push_back("cam" + std::to_string(left));
    names.push_back("cam" + std::to_string(left + 1));
    modules.push_back({s.name, left, left + 1, nominal_from_right.Inverse() * nominal_from_left});
    world_from_module.push_back(world_from_nominal * nominal_from_left);
    out.world_from_camera.push_back(world_from_nominal * nominal_from_left);
    out.world_from_camera.push_back(world_from_nominal * nominal_from_right);
    const Pose nominal_from_projector(
        Eigen::AngleAxisd(s.projector.rotation_deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
        s.projector.offset_mm);
    out.world_from_projector.push_back(world_from_nominal * nominal_from_projector);
    out.projector_distance_mm.push_back((s.look_at_mm - out.world_from_projector.back().translation_mm()).norm());
  }
  std::vector<Pose> module0_from_module;
  for (const Pose& p : world_from_module) module0_from_module.push_back(world_from_module[0].Inverse() * p);
  out.sim = SimulatedRig{Rig(std::move(cameras), std::move(names), std::move(modules), module0_from_module),
                         world_from_module[0]};
  out.sim.rig.provenance().tool = "stereorig simulator (ground truth)";
  return out;
}

}  // namespace stereorig
