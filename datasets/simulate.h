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
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "calib/core/lens_drift.h"
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

// At most this many worker threads: more than any machine's hardware threads
// today (two 128-core sockets give 512), and far below the per-user thread
// limits at which spawning fails (--threads 100000 died of an uncaught
// std::system_error, leaving its temporary folder behind).
constexpr int kMaxSimulateThreads = 1024;

struct SimulateOptions {
  // The dataset folder; replaced only if it is empty or an earlier dataset
  // holding nothing the simulator does not write (CheckReplaceableOut).
  std::string out_dir;
  uint64_t seed = 1;
  int threads = 0;                // 0 = every hardware thread; at most kMaxSimulateThreads
  bool scenes = true;             // false: calibration captures only
  int calibration_captures = -1;  // -1 = the spec's count
  RigBump bump;
  double surface_spacing_mm = 0.2;                   // ground-truth surface samples (<= 0.2)
  std::function<void(const std::string&)> progress;  // may be empty
  // Files the run reads besides the spec's target (which Simulate protects
  // itself), as (path, what): `stereorig simulate` gives its --spec file.
  // out_dir may not be one of them nor hold one: replacing it would delete it.
  std::vector<std::pair<std::string, std::string>> inputs;

  void Check() const;
};

struct SimulateSummary {
  int images = 0;           // PNGs written
  double seconds = 0;       // wall time
  double rays_seconds = 0;  // of which: unprojecting the ray tables
};

// Throws InputError naming `typed` (--out as given) unless the folder `out`
// (absolute, normalised) may be replaced by a new dataset: it does not
// exist, or is an empty folder, or is an earlier dataset (spec.yaml and
// truth/simulation.yaml of format stereorig-sim-info) holding only files and
// folders the simulator writes (the layout above). A file it does not
// write (notes, scores, a hand-written spec) is named, not deleted.
void CheckReplaceableOut(const std::string& typed, const std::filesystem::path& out);

// Throws InputError on a bad spec or option, if the output folder cannot
// be written or may not be replaced (CheckReplaceableOut), or if it is or
// holds an input (options.inputs, the spec's target file).
SimulateSummary Simulate(const SimSpec& spec, const SimulateOptions& options);

}  // namespace stereorig
