// `stereorig demo`: the whole product on the embedded default rig. Each step
// runs a real subcommand, through the same table and error handling, and
// prints the exact command line, shell-quoted, so a user can repeat any step
// by hand.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/demo_expectations.h"
#include "apps/demo_out.h"
#include "apps/output_paths.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// Runs `stereorig <args...>` in-process. Returns its exit code.
int Step(const std::vector<std::string>& args) {
  std::string line = "$ stereorig";
  for (const std::string& a : args) line += " " + ShellQuoted(a);
  std::printf("\n%s\n", line.c_str());
  FlushStdout();
  // The demo's output is its point: with stdout lost (a full disk,
  // /dev/full) no further step runs, and the demo ends in one line, exit 2.
  if (const std::string lost = StdoutWriteError(); !lost.empty())
    throw InputError("standard output",
                     "cannot be written: " + lost + "; the demo stops before `" + line.substr(2) + "`");
  for (const Command& c : Commands()) {
    if (args[0] != c.name) continue;
    std::vector<std::string> storage = args;
    storage[0] = "stereorig " + args[0];
    std::vector<char*> argv;
    for (std::string& s : storage) argv.push_back(s.data());
    const int rc = RunCommand(c, static_cast<int>(argv.size()), argv.data());
    FlushStdout();
    return rc;
  }
  STEREORIG_CHECK(false && "demo names an unknown subcommand");
  return kExitBadInput;
}

std::string Join(const std::string& dir, const std::string& name) {
  return (std::filesystem::path(dir) / name).string();
}

// The bump of step 5's second night, which its check must name.
constexpr int kBumpedCamera = 1;
constexpr const char* kBumpRotationDeg = "0.05";

// Which binary the printed `$ stereorig` lines mean, when a shell would not
// run this one for `stereorig` (a fresh build/stereorig, not installed):
// one line before the steps, so that they stay as the docs write them.
void PrintBinaryNote() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return;
  if (const std::string note = BinaryNote(self.string(), std::getenv("PATH")); !note.empty())
    std::printf("%s\n", note.c_str());
}

}  // namespace

int RunDemo(int argc, char** argv) {
  CLI::App app{
      "The whole product on the embedded default rig (2 facing modules, 752x582 cameras, 90 mm baseline, "
      "200 mm working distance, 51x51 laser grids): simulate a dataset, calibrate the rig from its target "
      "captures, reconstruct the cup (active and passive) and score it against the simulator's truth, verify the "
      "sphere and the ball bar (VDI/VDE 2634-2), and run the nightly check on fresh captures of the unmoved rig "
      "and of a bumped one. Every step prints the command it runs, so each can be repeated by hand.\n\n"
      "Exit codes: 0 every step behaved as expected (the verify figures pass, the check is ok on the unmoved rig "
      "and names the bumped camera alone); 1 a step did not (a line 'demo: STEP: exit N, expected M', or 'demo: "
      "STEP: ...' saying what its report named instead, names it; a failed simulate or calibrate ends the demo "
      "there); 2 "
      "bad usage, or an --out that cannot be made.\n\n"
      "Example:\n  stereorig demo --out /tmp/stereorig-demo",
      "stereorig demo"};
  std::string out = "stereorig-demo";
  uint64_t seed = 1;
  app.add_option("--out", out,
                 "folder for everything the demo writes (created if missing); one that is not empty must be an "
                 "earlier demo's, holding nothing else")
      ->capture_default_str()
      ->check(NonEmptyPath());
  // The night's and the bumped datasets take seed + 100 and seed + 200.
  AddSeedOption(app, &seed, std::numeric_limits<uint64_t>::max() - 200, "simulator seed");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  // Made at once (nothing after this is bad input), and, if it cannot be
  // made, none of it left (apps/output_paths.h).
  FolderToCreate out_folder = OutputPaths().ClaimFolder(out, "everything the demo writes (--out)");
  CheckDemoOut(out);  // the user's files in it are not replaced
  out_folder.Create();
  PrintBinaryNote();
  const std::string ds = Join(out, "dataset"), rig = Join(out, "rig.yaml");
  const std::string s = std::to_string(seed);
  int failures = 0;
  auto expect = [&failures](int rc, int expected, const char* what) {
    if (rc != expected) {
      std::printf("demo: %s: exit %d, expected %d\n", what, rc, expected);
      ++failures;
    }
    return rc == expected;
  };

  std::printf("== 1. simulate the default rig: target captures, object scenes, ground truth\n");
  if (!expect(Step({"simulate", "--out", ds, "--seed", s}), kExitOk, "simulate")) return kExitCheckFailed;

  std::printf("\n== 2. calibrate: mrcal intrinsics, stereo extrinsics, Horn + Ceres across the modules\n");
  if (!expect(
          Step({"calibrate", "--captures", ds, "--target", Join(ds, "target.yaml"), "--layout", Join(ds, "layout.yaml"),
                "--out", rig, "--report", Join(out, "calibration.json"), "--export-cameramodels", out}),
          kExitOk, "calibrate"))
    return kExitCheckFailed;

  std::printf("\n== 3. reconstruct the cup, active (laser grids on) and passive, with the calibrated rig\n");
  // The default options are the grid's: the passive capture (no grid) is
  // matched over the whole volume and without the grid's own tests, as the
  // options guide says (docs/reconstruct.md) and score's passive run does
  // (PassiveOptions, runtime_options.h), from a file the user can reuse.
  const std::string passive_options = Join(out, "passive_options.yaml");
  WriteFileAtomically(passive_options,
                      "# Runtime options for a capture without the laser grids (docs/reconstruct.md).\n"
                      "crop_to_lit_region: false\nmatch:\n  min_distinctness: 0\n  grid_line_test: false\n"
                      "  line_index: false\n");
  for (const char* mode : {"active", "passive"}) {
    const std::string name = std::string("cup_") + mode;
    std::vector<std::string> args = {"reconstruct",
                                     "--rig",
                                     rig,
                                     "--capture",
                                     Join(ds, std::string("scenes/cup/") + mode),
                                     "--out",
                                     Join(out, name + ".ply"),
                                     "--mesh",
                                     Join(out, name + "_mesh.ply"),
                                     "--report",
                                     Join(out, name + ".json")};
    if (std::string(mode) == "passive") args.insert(args.end(), {"--options", passive_options});
    expect(Step(args), kExitOk, "reconstruct");
  }
  std::printf("\n== 3b. the cup against the simulator's truth: accuracy, fill, active/passive points\n");
  expect(Step({"score", "--dataset", ds, "--rig", rig, "--scenes", "cup", "--report", Join(out, "score_cup.json")}),
         kExitOk, "score");

  std::printf("\n== 4. verify: VDI/VDE 2634-2 figures on the sphere and the ball bar\n");
  // The simulator writes each artifact's certificate (its true dimensions)
  // beside the dataset, as a calibration lab would deliver it.
  const std::string artifacts = Join(ds, "artifacts");
  for (const auto& [scene, artifact] : {std::pair{"sphere", "sphere.yaml"}, {"ballbar", "ballbar.yaml"}}) {
    const std::string cloud = Join(out, std::string(scene) + ".ply");
    expect(Step({"reconstruct", "--rig", rig, "--capture", Join(ds, std::string("scenes/") + scene + "/active"),
                 "--out", cloud}),
           kExitOk, "reconstruct");
    expect(Step({"verify", "--artifact", artifacts + "/" + artifact, "--cloud", cloud, "--report",
                 Join(out, std::string("verify_") + scene + ".json")}),
           kExitOk, "verify");
  }

  std::printf("\n== 5. the nightly check: 8 fresh target captures of the unmoved rig, then after a bump\n");
  const std::string night = Join(out, "night_ok"), bumped = Join(out, "night_bumped");
  const std::string history = Join(out, "check-history.sqlite");
  std::error_code ec;
  // With SQLite's own files an interrupted check may have left: a hot
  // journal beside a new history would be rolled back into it.
  for (const char* suffix : {"", "-journal", "-wal", "-shm"}) std::filesystem::remove(history + suffix, ec);
  expect(Step({"simulate", "--out", night, "--seed", std::to_string(seed + 100), "--calibration-captures", "8",
               "--no-scenes"}),
         kExitOk, "simulate (night)");
  expect(Step({"check", "--rig", rig, "--captures", night, "--target", Join(ds, "target.yaml"), "--history-db", history,
               "--report", Join(out, "check_ok.json")}),
         kExitOk, "check (unmoved rig)");
  expect(Step({"simulate", "--out", bumped, "--seed", std::to_string(seed + 200), "--calibration-captures", "8",
               "--no-scenes", "--bump-camera", std::to_string(kBumpedCamera), "--bump-rotation-deg", kBumpRotationDeg}),
         kExitOk, "simulate (bumped)");
  const std::string bumped_check = "check (camera " + std::to_string(kBumpedCamera) + " bumped by " + kBumpRotationDeg +
                                   " deg: must say recalibrate, naming it)";
  const std::string bumped_report = Join(out, "check_bumped.json");
  if (expect(Step({"check", "--rig", rig, "--captures", bumped, "--target", Join(ds, "target.yaml"), "--history-db",
                   history, "--report", bumped_report}),
             kExitCheckFailed, bumped_check.c_str())) {
    // Exit 1 is any recalibrate; the README promises the bumped camera named.
    if (const std::string surprise = BumpedNightSurprise(bumped_report, kBumpedCamera); !surprise.empty()) {
      std::printf("demo: %s: %s\n", bumped_check.c_str(), surprise.c_str());
      ++failures;
    }
  }
  expect(Step({"check", "--history", "--history-db", history}), kExitOk, "check --history");

  if (failures) {
    std::printf(
        "\n== demo FINISHED WITH SURPRISES: %d step(s) did not behave as expected (the 'demo:' lines above); "
        "everything is in %s\n",
        failures, out.c_str());
    return kExitCheckFailed;
  }
  std::printf(
      "\n== demo done: every step behaved as expected; the bumped night's `recalibrate` naming camera %d "
      "was the expected outcome (the check caught the bump).\n== everything is in %s\n",
      kBumpedCamera, out.c_str());
  return kExitOk;
}

}  // namespace stereorig
