// The simulator's rig spec: everything `stereorig simulate` renders, as one
// plain YAML file (docs/simulator.md, "Spec file"). The embedded default is
// the seed paper's rig (../shared/BRIEF.md, "The default rig").
//
// World frame of the simulator: the measurement volume is centred on the
// origin, y points down (gravity), the conveyor runs along x. Each module is
// placed by its nominal centre (midway between its two cameras) and the
// point it looks at. A module's nominal frame: z towards `look_at_mm`, x along
// the baseline from the left to the right camera, y down (as the cameras').
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/core/pose.h"
#include "datasets/default_rig.h"

namespace stereorig {

struct CameraSpec {
  std::string lensmodel = "LENSMODEL_OPENCV8";  // any model, spelled as mrcal spells it
  std::vector<double> intrinsics;               // mrcal's order for that model
  int width_px = 752;
  int height_px = 582;
};

// One laser DOE: a grid of N x N lines. Lines of one family are where the
// direction cosine u_x of the ray from the projector (its frame: z along the
// optical axis, turned by `rotation_deg` about z) equals
// sin(fan/2) * (2i/(N-1) - 1), i = 0..N-1, as the grating equation of a
// crossed DOE gives; the other family is the same in u_y.
struct ProjectorSpec {
  bool enabled = true;
  Eigen::Vector3d offset_mm = Eigen::Vector3d::Zero();  // in the module's nominal frame; default: midway
  int lines = 51;                                       // N lines per family
  double fan_angle_deg = 23.0;                          // full fan, outermost line to outermost line
  double rotation_deg = 2.6;                            // about the projector axis, against the camera rows
  double line_sigma_mrad = 1.0;  // Gaussian 1-sigma of a line's profile (0.2 mm at 200 mm, ~1 px)
  double power_dn = 110.0;       // a line centre on albedo 1, facing, at the working distance (DN)
};

struct ModuleSpec {
  std::string name;
  Eigen::Vector3d center_mm = Eigen::Vector3d(0, 0, -200);  // nominal centre, world frame
  Eigen::Vector3d look_at_mm = Eigen::Vector3d::Zero();     // world frame
  Eigen::Vector3d up = Eigen::Vector3d(0, -1, 0);           // world direction that appears up in the images
  double baseline_mm = 90.0;
  double verging_deg = 6.0;  // angle between the two optical axes (inward)
  CameraSpec left, right;
  ProjectorSpec projector;
};

// Light, optics and sensor. DN = 8-bit grey levels.
struct RenderSpec {
  int samples_per_axis = 2;             // scenes: n x n stratified rays per pixel (>= 2, i.e. >= 4 spp)
  int edge_samples_per_axis = 8;        // target: n x n samples in pixels that straddle a print edge
  double ambient_dn = 190.0;            // albedo-1 surface facing up-ish under the room light (DN)
  double ambient_directional = 0.5;     // share of the room light that comes from above (0 = all diffuse)
  double background_dn = 10.0;          // nothing hit: the far, dark surroundings (DN)
  double stray_light_dn = 6.0;          // veiling glare: a smooth additive ramp across the image, mean (DN)
  double psf_sigma_px = 0.6;            // optical blur, Gaussian 1-sigma (px)
  bool noise = true;                    // shot + read noise (false: ideal sensor, still quantised)
  double full_well_e = 10000.0;         // electrons at 255 DN: sets the shot noise
  double read_noise_e = 12.0;           // read noise, 1-sigma (electrons)
  double speckle_contrast = 0.2;        // laser speckle, 1-sigma relative, independent per camera (0 = off)
  double speckle_grain_px = 1.0;        // speckle grain, Gaussian 1-sigma (px)
  double texture_contrast = 0.03;       // weak texture: relative albedo variation amplitude
  double texture_wavelength_mm = 15.0;  // its typical wavelength

  void Check(const std::string& where) const;
};

struct CalibrationSpec {
  int captures = 50;                                           // target poses, lasers off
  std::string target = "default";                              // "default" = DefaultTarget(), or a target file;
                                                               // relative: from the spec file's folder
  double tilt_max_deg = 40.0;                                  // board tilt out of the view plane
  double roll_max_deg = 30.0;                                  // board rotation in its plane
  Eigen::Vector3d volume_mm = Eigen::Vector3d(150, 150, 100);  // where the board centre may go (x, y, z)
  double scale_error_ppm = 0.0;        // printed board larger than nominal by this (ppm); the target file keeps nominal
  double back_misalignment_deg = 0.0;  // back print turned in plane against the ideal, degrees
  double back_misalignment_mm = 0.0;   // back print shifted in plane (along x) against the ideal, mm
  double nonflatness_mm = 0.0;         // bow of the plate: peak deviation from the plane at its centre, mm
  double white_albedo = 0.85;          // printed white
  double black_albedo = 0.04;          // printed black
  int min_corners_per_camera = 12;     // a pose is redrawn until every camera sees at least this many corners

  void Check(const std::string& where) const;
};

struct ScenesSpec {
  std::vector<std::string> names = {"cup", "sphere", "ballbar", "plate", "tuber"};
  double wobble_shift_mm = 5.0;  // conveyor: transverse (z) and along-belt (x) shift, uniform +-
  double wobble_tilt_deg = 3.0;  // conveyor: rocking tilt about x and z, uniform +-
  double cup_diameter_mm = 75.0;
  double cup_height_mm = 80.0;
  double cup_albedo = 0.8;  // glazed white ceramic (diffuse part)
  double sphere_diameter_mm = 38.1;
  double ballbar_sphere_diameter_mm = 25.4;
  double ballbar_distance_mm = 80.0;
  Eigen::Vector3d plate_size_mm = Eigen::Vector3d(130, 120, 8);
  Eigen::Vector3d tuber_semi_axes_mm = Eigen::Vector3d(42, 30, 27);
  double tuber_bump = 0.05;      // relative radial bump amplitude
  double artifact_albedo = 0.7;  // matte grey spheres, ball bar, plate
  double tuber_albedo = 0.45;

  void Check(const std::string& where) const;
};

struct SimSpec {
  std::vector<ModuleSpec> modules;
  RenderSpec render;
  CalibrationSpec calibration;
  ScenesSpec scenes;

  // Throws InputError naming the key.
  void Check(const std::string& where = "spec") const;
};

// The seed paper's rig; its cameras are exactly MakeDefaultRig()'s.
SimSpec DefaultSimSpec();

// Strict reading: unknown keys, wrong types and bad values throw InputError
// naming the file and key. Missing optional keys keep the defaults above.
// ReadSimSpecFile reads a relative calibration.target from the spec file's
// folder (the returned spec holds that path) and refuses one that is not a
// file; ParseSimSpecYaml, with no file, leaves it as written.
SimSpec ReadSimSpecFile(const std::string& path);
SimSpec ParseSimSpecYaml(const std::string& text, const std::string& where);
std::string SimSpecToYaml(const SimSpec& spec);

// The true rig a spec describes, placed in the world.
struct SpecRig {
  SimulatedRig sim;                           // rig + world_from_module0
  std::vector<Pose> world_from_camera;        // per global camera
  std::vector<Pose> world_from_projector;     // per module (z = projector axis, grid rotation applied)
  std::vector<double> projector_distance_mm;  // per module: projector to look-at point
};
SpecRig BuildSpecRig(const SimSpec& spec);

}  // namespace stereorig
