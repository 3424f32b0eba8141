// The whole simulator: a spec in, a dataset folder out (docs/simulator.md,
// "Dataset layout"):
//
//   DIR/spec.yaml, DIR/target.yaml, DIR/layout.yaml
//   DIR/calibration/NNN/camK.png            lasers off
//   DIR/scenes/<scene>/{active,passive}/camK.png
//   DIR/truth/rig.yaml                      true rig, reference = module 0
//   DIR/truth/calibration_poses.yaml
//   DIR/truth/simulation.yaml               seed, knobs that are not in the spec (bumps)
//   DIR/truth/scenes/<scene>/{object.yaml, surface.ply, depth_camK.tiff, id_camK.png, lit_camK.png}
//
// The folder appears atomically: everything is written to a sibling temporary
// folder that is renamed into place at the end. The same spec and seed give
// the same bytes, whatever the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "datasets/lens_drift.h"
#include "datasets/sim_spec.h"

namespace stereorig {

// "The morning after a bump": the true rig moved, or one camera's lens
// drifted, before rendering.
struct RigBump {
  int camera = -1;              // global camera index to disturb, -1 = none
  int module = -1;              // module index to move as a whole (its cameras and projector), -1 = none
  double rotation_deg = 0.0;    // angle of the disturbance, about an axis drawn from the seed
  double translation_mm = 0.0;  // length of the shift, along a direction drawn from the seed
  LensDrift lens;               // the bumped camera's intrinsics drift (with `camera` only: a lens is one camera's)
  bool Any() const { return (camera >= 0 || module >= 0) && (rotation_deg != 0 || translation_mm != 0 || lens.Any()); }
};

struct SimulateOptions {
  std::string out_dir;  // the dataset folder; replaced only if it is empty or a dataset
  uint64_t seed = 1;
  int threads = 0;                // 0 = every hardware thread
  bool scenes = true;             // false: calibration captures only
  int calibration_captures = -1;  // -1 = the spec's count
  RigBump bump;
  double surface_spacing_mm = 0.2;                   // ground-truth surface samples (<= 0.2)
  std::function<void(const std::string&)> progress;  // may be empty

  void Check() const;
};

struct SimulateSummary {
  int images = 0;           // PNGs written
  double seconds = 0;       // wall time
  double rays_seconds = 0;  // of which: unprojecting the ray tables
};

// Throws InputError on a bad spec or option, or if the output folder cannot
// be written.
SimulateSummary Simulate(const SimSpec& spec, const SimulateOptions& options);

}  // namespace stereorig
