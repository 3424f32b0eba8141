// The rig: every camera, every stereo module, and the M x M S matrix.
//
// Frames (docs/conventions.md):
//   - a camera frame: x right, y down, z forward along the optical axis, mm;
//   - a module frame IS its left (reference) camera's frame;
//   - the rig's reference frame is module 0's frame.
// S[i][j] = module_i_from_module_j. The rig enforces S_ii = I,
// S_ji = S_ij^-1 and S_ij * S_jk = S_ik within the tolerances below.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "camera.h"
#include "pose.h"

namespace stereorig {

struct StereoModule {
  std::string name;       // e.g. "module0"
  int left_camera = -1;   // index into Rig::cameras(); the module's reference camera
  int right_camera = -1;  // index into Rig::cameras()
  Pose right_from_left;   // right camera from left camera (= module) frame, mm
};

// The board a rig was calibrated with, as the calibration used it: what the
// nightly check must measure with again (calib/check/check_target.h). Stage 3
// refines the target file's back_from_front under the file's stated sigma
// jointly with S, so S holds with that estimate, not with the file's.
struct CalibrationTarget {
  std::string file;             // the target file calibrate was given, its absolute path (empty if none)
  int corners_x = 0;            // inner corners along a row
  int corners_y = 0;            // inner corners along a column
  double square_size_mm = 0.0;  // printed square edge
  bool double_sided = false;
  Pose back_from_front;       // as calibrated: stage 3's estimate (the file's where it was held, or one module)
  Pose back_from_front_file;  // as the target file gave it
  // The file's 1-sigma of back_from_front_file: [rx, ry, rz] deg, [tx, ty, tz] mm.
  Eigen::Matrix<double, 6, 1> back_from_front_sigma_file = Eigen::Matrix<double, 6, 1>::Zero();
};

// Where a rig came from. The same structure serves a calibration result and
// the simulator's ground truth.
struct Provenance {
  std::string tool;      // e.g. "stereorig 0.1.0"
  std::string date_utc;  // ISO 8601, e.g. "2026-11-23T13:00:00Z"
  std::string input;     // the dataset or capture folder it was made from
  // Per-stage RMS residuals, e.g. {"intrinsics_rms_px": 0.2, ...}.
  std::map<std::string, double> residuals;
  // 1-sigma uncertainties, e.g. {"S_0_1_translation_mm": 0.01, ...}.
  std::map<std::string, double> uncertainties;
  // The calibration's board; absent in the simulator's truth and in rig
  // files written before stereorig recorded it.
  std::optional<CalibrationTarget> target;
};

// Tolerances of the S invariants. A rig file written with %.17g and composed
// in double precision holds them to ~1e-13 (translations of ~1e3 mm); these
// leave margin for a file edited by another tool that prints ~12 digits,
// while still catching any inconsistency of metrological size (1 nm, 1e-9 rad).
inline constexpr double kSRotationTolerance = 1e-9;  // max |element| difference of R
inline constexpr double kSTranslationToleranceMm = 1e-6;

class Rig {
 public:
  Rig() = default;
  // Builds a consistent S from each module's pose in the reference frame:
  // module0_from_module[i] (module0_from_module[0] must be identity).
  Rig(std::vector<Camera> cameras, std::vector<std::string> camera_names, std::vector<StereoModule> modules,
      const std::vector<Pose>& module0_from_module);
  // Takes a full S as given; throws InputError(`where`, ...) if it breaks an
  // invariant, or if modules name cameras that do not exist. `where` (the
  // rig file's path) is kept as source().
  Rig(std::vector<Camera> cameras, std::vector<std::string> camera_names, std::vector<StereoModule> modules,
      std::vector<std::vector<Pose>> S, const std::string& where);

  int num_modules() const { return static_cast<int>(modules_.size()); }
  int num_cameras() const { return static_cast<int>(cameras_.size()); }
  const std::vector<Camera>& cameras() const { return cameras_; }
  const std::vector<std::string>& camera_names() const { return camera_names_; }
  const std::vector<StereoModule>& modules() const { return modules_; }
  const Camera& camera(int i) const { return cameras_.at(i); }
  const StereoModule& module(int i) const { return modules_.at(i); }

  // S[i][j] = module_i_from_module_j.
  const Pose& S(int i, int j) const { return S_.at(i).at(j); }
  const std::vector<std::vector<Pose>>& S() const { return S_; }
  // A camera's pose relative to the reference frame (module 0):
  // cam_from_module0 = cam_from_module_i * module_i_from_module0.
  Pose CamFromReference(int camera_index) const;

  // Where the rig was read from (the `where` it was built with; empty for a
  // rig built in memory), and the `where` of later messages about it: the
  // source, or "rig" when there is none.
  const std::string& source() const { return source_; }
  std::string Where() const { return source_.empty() ? "rig" : source_; }

  Provenance& provenance() { return provenance_; }
  const Provenance& provenance() const { return provenance_; }

  // Checks S_ii = I, S_ji = S_ij^-1, S_ij S_jk = S_ik and rigidity. On failure
  // returns false and names the entry in `why`.
  bool CheckS(std::string* why) const;

 private:
  void CheckTopology(const std::string& where) const;

  std::vector<Camera> cameras_;
  std::vector<std::string> camera_names_;
  std::vector<StereoModule> modules_;
  std::vector<std::vector<Pose>> S_;
  Provenance provenance_;
  std::string source_;
};

}  // namespace stereorig
