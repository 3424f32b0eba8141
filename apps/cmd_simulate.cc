// `stereorig simulate`: render a rig spec into a dataset with ground truth.
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "datasets/sim_spec.h"
#include "datasets/simulate.h"

namespace stereorig {

int RunSimulate(int argc, char** argv) {
  CLI::App app{
      "Render a rig spec into a dataset with ground truth: target captures (lasers off), active and passive "
      "object scenes (cup, sphere, ball bar, plate, tuber), the true rig, target poses, depth and ID maps, "
      "analytic objects and dense surfaces. Without --spec, the embedded default rig (2 facing modules, "
      "752x582 cameras, 90 mm baseline, 200 mm working distance, 51x51 laser grid). The same spec and seed "
      "give the same bytes. docs/simulator.md describes every knob.\n\n"
      "Exit codes: 0 ok (its warnings too); 2 bad usage or input (a folder it refuses to replace included).\n\n"
      "Examples:\n"
      "  stereorig simulate --out data/default --seed 1\n"
      "  stereorig simulate --write-default-spec my_rig.yaml     # edit it, then:\n"
      "  stereorig simulate --spec my_rig.yaml --out data/my_rig\n"
      "  stereorig simulate --out data/bumped --bump-camera 1 --bump-rotation-deg 0.05 \\\n"
      "      --calibration-captures 8 --no-scenes                # the morning after a bump\n"
      "  stereorig simulate --out data/refocused --bump-camera 2 --bump-focal-percent 0.1 \\\n"
      "      --calibration-captures 8 --no-scenes                # camera 2's focus ring turned",
      "stereorig simulate"};
  std::string spec_path, write_spec;
  SimulateOptions o;
  bool no_scenes = false;
  app.add_option("--spec", spec_path, "rig spec YAML (default: the embedded default rig)");
  app.add_option("--out", o.out_dir,
                 "dataset folder to write; an earlier dataset there is replaced whole, atomically, and only if it "
                 "holds nothing the simulator does not write (else exit 2, naming the file)")
      ->check(NonEmptyPath());
  AddSeedOption(app, &o.seed, std::numeric_limits<uint64_t>::max(), "random seed: poses, scenes, noise");
  app.add_option("--threads", o.threads,
                 "worker threads, in [0, " + std::to_string(kMaxSimulateThreads) +
                     "] (0 = all cores; never more than the jobs)")
      ->capture_default_str();
  app.add_option("--calibration-captures", o.calibration_captures,
                 "override the spec's number of target captures, in [0, 999]");
  app.add_flag("--no-scenes", no_scenes, "render the calibration captures only");
  app.add_option("--write-default-spec", write_spec, "write the embedded default spec to this file and exit");
  app.add_option("--bump-camera", o.bump.camera, "disturb this camera (global index) before rendering");
  app.add_option("--bump-module", o.bump.module, "move this module (cameras and projector) as a whole");
  app.add_option("--bump-rotation-deg", o.bump.rotation_deg,
                 "bump: rotation angle, about a seeded random axis; within +-10");
  app.add_option("--bump-translation-mm", o.bump.translation_mm,
                 "bump: shift, along a seeded random direction; within +-10");
  app.add_option("--bump-focal-percent", o.bump.lens.focal_percent,
                 "bump the camera's lens: fx and fy scaled by 1 + P/100 (a focus ring turned, thermal drift); "
                 "within +-10");
  std::vector<double> principal_point_px;
  app.add_option("--bump-principal-point-px", principal_point_px,
                 "bump the camera's lens: its principal point moved by DX DY px; each within +-50")
      ->expected(2);
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  if (principal_point_px.size() == 2) o.bump.lens.principal_point_px = {principal_point_px[0], principal_point_px[1]};
  if (!write_spec.empty())
    for (const char* flag :
         {"--out", "--seed", "--threads", "--calibration-captures", "--no-scenes", "--bump-camera", "--bump-module",
          "--bump-rotation-deg", "--bump-translation-mm", "--bump-focal-percent", "--bump-principal-point-px"})
      if (app.count(flag) > 0)
        throw InputError(flag, "does not apply with --write-default-spec (it writes the spec and stops)");
  // -1 is the options' "none": given, it named no camera, and the bump read
  // as "every amount given is 0" whatever the amount.
  if (app.count("--bump-camera") > 0 && o.bump.camera < 0)
    throw InputError("--bump-camera", "no camera " + std::to_string(o.bump.camera));
  if (app.count("--bump-module") > 0 && o.bump.module < 0)
    throw InputError("--bump-module", "no module " + std::to_string(o.bump.module));
  // Likewise -1 is the options' "the spec's count": given, it rendered the
  // spec's captures as if the flag were absent.
  if (app.count("--calibration-captures") > 0 && o.calibration_captures < 0)
    throw InputError("--calibration-captures", "must be in [0, 999]");
  // A bump needs what to move and by how much: either alone used to render
  // an undisturbed rig without a word. A lens drift needs its camera.
  const bool bump_what = app.count("--bump-camera") + app.count("--bump-module") > 0;
  const bool bump_motion = app.count("--bump-rotation-deg") + app.count("--bump-translation-mm") > 0;
  const bool bump_lens = app.count("--bump-focal-percent") + app.count("--bump-principal-point-px") > 0;
  if (bump_lens && app.count("--bump-camera") == 0)
    throw InputError(app.count("--bump-focal-percent") ? "--bump-focal-percent" : "--bump-principal-point-px",
                     "needs --bump-camera (a lens drifts in one camera, not in a whole module)");
  if (bump_motion && !bump_what)
    throw InputError(app.count("--bump-rotation-deg") ? "--bump-rotation-deg" : "--bump-translation-mm",
                     "needs --bump-camera or --bump-module (what to move)");
  if (bump_what && !bump_motion && !bump_lens)
    throw InputError(app.count("--bump-camera") ? "--bump-camera" : "--bump-module",
                     app.count("--bump-camera")
                         ? "needs --bump-rotation-deg, --bump-translation-mm, --bump-focal-percent or "
                           "--bump-principal-point-px (by how much)"
                         : "needs --bump-rotation-deg or --bump-translation-mm (by how much)");
  if (bump_what && !o.bump.Any())  // every amount given is 0 (NaN and bounds: the options' checks)
    throw InputError(app.count("--bump-camera") ? "--bump-camera" : "--bump-module",
                     "every amount given is 0: the rig would render undisturbed; give a nonzero amount");

  // A --spec given is read below, or, beside --write-default-spec, only
  // protected from being overwritten: checked here either way, so that a
  // missing one is not passed over with exit 0.
  // A pipe too (`--spec <(...)`): ReadSimSpecFile reads it once, start to
  // end, as a rig file or --options is read.
  if (!spec_path.empty()) RequireInputFile(spec_path, /*pipe_too=*/true);
  if (!write_spec.empty()) {
    // Checked like every other command's outputs (apps/output_paths.h): its
    // folder exists, it is not a folder, and it is not the --spec file given
    // alongside (which the default would replace).
    OutputPaths outputs;
    outputs.Protect(spec_path, "the spec file (--spec)");
    outputs.Claim(write_spec, "the default spec (--write-default-spec)");
    WriteFileAtomically(write_spec, SimSpecToYaml(DefaultSimSpec()));
    std::printf("wrote the default spec to %s\n", write_spec.c_str());
    return kExitOk;
  }
  o.scenes = !no_scenes;
  const SimSpec spec = spec_path.empty() ? DefaultSimSpec() : ReadSimSpecFile(spec_path);
  // Replacing --out whole would delete the spec inside it (its target
  // file Simulate protects itself).
  if (!spec_path.empty()) o.inputs.push_back({spec_path, "the spec file (--spec)"});
  o.progress = [](const std::string& s) { std::fprintf(stderr, "simulate: %s\n", s.c_str()); };
  const SimulateSummary s = Simulate(spec, o);
  std::printf("wrote %s: %d images in %.1f s (ray tables %.1f s)\n", o.out_dir.c_str(), s.images, s.seconds,
              s.rays_seconds);
  return kExitOk;
}

}  // namespace stereorig
