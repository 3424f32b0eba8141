// The subcommand table. Adding a subcommand = one RunX in its own cmd_x.cc
// and one line here.
#include "apps/cli_util.h"
#include "apps/command.h"

namespace stereorig {

int RunDemo(int argc, char** argv);
int RunRig(int argc, char** argv);
int RunSimulate(int argc, char** argv);

namespace {

int RunTarget(int argc, char** argv) {
  return NotBuiltYet("target", "Write a printable double-sided target at true scale.", argc, argv);
}
int RunCalibrate(int argc, char** argv) {
  return NotBuiltYet("calibrate", "Images + target + layout -> rig file + report.", argc, argv);
}
int RunReconstruct(int argc, char** argv) {
  return NotBuiltYet("reconstruct", "Rig file + capture -> point cloud, mesh, report.", argc, argv);
}
int RunMatch(int argc, char** argv) {
  return NotBuiltYet("match", "The correspondence stage alone, on a rectified pair -> disparity (PFM).", argc, argv);
}
int RunVerify(int argc, char** argv) {
  return NotBuiltYet("verify", "A reconstruction of a reference artifact -> accuracy figures, pass/fail.", argc, argv);
}
int RunCheck(int argc, char** argv) {
  return NotBuiltYet("check", "Nightly check: fresh target captures + rig file -> drift verdict, history.", argc,
                     argv);
}
int RunBench(int argc, char** argv) {
  return NotBuiltYet("bench", "Throughput of the runtime, side by side with an OpenCV StereoSGBM pipeline.", argc,
                     argv);
}

}  // namespace

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      {"simulate", "render a rig spec into a dataset with ground truth", &RunSimulate},
      {"target", "write a printable double-sided target at true scale (SVG)", &RunTarget},
      {"calibrate", "images + target + layout -> rig file + report", &RunCalibrate},
      {"reconstruct", "rig file + capture -> point cloud, mesh, report", &RunReconstruct},
      {"match", "correspondence alone on a rectified pair -> disparity (PFM)", &RunMatch},
      {"verify", "reconstruction of a reference artifact -> VDI/VDE 2634-2 figures, pass/fail", &RunVerify},
      {"check", "nightly check: fresh target captures + rig file -> drift verdict", &RunCheck},
      {"bench", "throughput, side by side with an OpenCV StereoSGBM pipeline", &RunBench},
      {"rig", "inspect a rig file: validate, summarise, export .cameramodel files", &RunRig},
      {"demo", "run every stage built so far on the embedded default rig", &RunDemo},
  };
  return commands;
}

}  // namespace stereorig
