// The calibration engine's entry point: corner observations -> a Rig (with
// provenance) and a report holding every figure of the three stages.
//
//   Stage 1: each camera's intrinsics (intrinsics.h).
//   Stage 2: each module's right_from_left, joint with both lenses (stereo.h).
//   Stage 3: the S matrix: Horn, then one bundle adjustment (system.h).
//
// Bad input (too few views, a degenerate set, a camera that never sees the
// board, a corner outside its imager, a face seen by the wrong module, ...) is
// refused with an InputError that names the problem.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "calib/intrinsics.h"
#include "calib/observations.h"
#include "calib/stereo.h"
#include "calib/system.h"

namespace stereorig {

struct CalibrationOptions {
  IntrinsicsOptions intrinsics;
  StereoOptions stereo;
  SystemOptions system;
  bool progress = false;  // one line per step on stderr; default false
  void Check() const;
};

struct CalibrationReport {
  std::string source;
  std::vector<IntrinsicsReport> intrinsics;  // stage 1, per camera
  std::vector<StereoReport> stereo;          // stage 2, per module
  SystemReport system;                       // stage 3 (empty for a 1-module rig)
  int num_modules = 0;
  std::map<int, std::string> capture_names;  // CalibrationInput::capture_names
  // The limit every stage was held to (IntrinsicsOptions::max_rms_px) and,
  // if one stayed over it, NotConvergedProblem's line (calib/convergence.h;
  // "" if all converged). Stage 1 over it: stages 2 and 3 are not run.
  double max_rms_px = 0.0;
  std::string not_converged;
  // Stage 3's refined back_from_front far beyond the target file's stated
  // sigma (SystemReport::back_from_front_vs_file over
  // SamePlateChiSquare(axes), the axes refined): one line saying by how
  // much and on which axis, for the message refusing the rig file; "" if
  // within, or not refined (one module, every sigma 0).
  std::string wrong_plate;
  // The warnings calibrate printed on stderr ("calibrate: warning: ..."),
  // one line each: cameras of the captures no module names, most images
  // rejected, rows or columns of the target never seen, views that repeat a
  // board pose, views stage 2 left out (capture_folder.h); and Calibrate's
  // own: a stage 3 Horn-only solve that stopped short
  // (SystemReport::horn_only_solver_problem).
  std::vector<std::string> warnings{};
  // The capture's folder name where known, else its index in decimal: how
  // the summary names a capture (the JSON keeps the index and adds the name).
  std::string CaptureName(int capture) const;
  std::string ToJson() const;
};

struct CalibrationResult {
  Rig rig;
  CalibrationReport report;
  std::vector<IntrinsicsResult> stage1;  // per camera
  std::vector<StereoResult> stage2;      // per module
  SystemResult stage3;
};

// Validates `input` (throws InputError) and runs the three stages. Where a
// camera's stage 1 did not converge (report.not_converged), it stops there:
// the result holds stage 1 and the report only, no rig (an empty Rig).
CalibrationResult Calibrate(const CalibrationInput& input, const CalibrationOptions& options);

// The input checks alone (throws InputError on the first problem).
void ValidateInput(const CalibrationInput& input);

// Writes every camera of `rig` as DIR/<camera name>.cameramodel (mrcal's
// format, %.17g), with extrinsics = cam_from_module0, all or none
// (AtomicOutputSet). Returns the paths written.
std::vector<std::string> ExportCameramodels(const Rig& rig, const std::string& dir);

// A readable summary of every stage (a few lines per camera and module).
std::string SummaryText(const CalibrationReport& report);

// Writes the rig file, the JSON report and, if cameramodels_dir is given,
// ExportCameramodels' files there, all or none (AtomicOutputSet): a model
// that cannot be written leaves an earlier run's rig file as it was. A
// camera no lens could be (lens_plausibility.h), or a stage that did not
// converge (report.not_converged, convergence.h), writes the report alone
// and throws InputError naming the rig file: its readers would refuse the
// first, and the second would measure nothing to its figures. A plate far
// from its file (report.wrong_plate) writes the report alone and throws
// InputError naming the target file (the rig's record of it, "the target
// file" without one): S rests on a back_from_front the file contradicts.
void WriteCalibrationOutputs(const CalibrationResult& result, const std::string& rig_path,
                             const std::string& report_path, const std::string& cameramodels_dir = "");

}  // namespace stereorig
