// The subcommand table. Adding a subcommand = one RunX in its own cmd_x.cc
// and one line here.
#include "apps/command.h"

namespace stereorig {

int RunSimulate(int argc, char** argv);
int RunTarget(int argc, char** argv);
int RunCalibrate(int argc, char** argv);
int RunReconstruct(int argc, char** argv);
int RunMatch(int argc, char** argv);
int RunVerify(int argc, char** argv);
int RunCheck(int argc, char** argv);
int RunBench(int argc, char** argv);
int RunScore(int argc, char** argv);
int RunRig(int argc, char** argv);
int RunTune(int argc, char** argv);
int RunDemo(int argc, char** argv);

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      {"simulate", "render a rig spec into a dataset with ground truth", &RunSimulate},
      {"target", "write a printable double-sided target at true scale (SVG)", &RunTarget},
      {"calibrate", "images + target + layout -> rig file + report", &RunCalibrate},
      {"reconstruct", "rig file + capture -> point cloud, mesh, report", &RunReconstruct},
      {"match", "correspondence alone on a rectified pair -> disparity (PFM)", &RunMatch},
      {"verify", "reconstruction of a reference artifact -> VDI/VDE 2634-2 figures, pass/fail", &RunVerify},
      {"check", "nightly check: fresh target captures + rig file -> drift verdict, history", &RunCheck},
      {"bench", "throughput, side by side with an OpenCV StereoSGBM pipeline", &RunBench},
      {"score", "the runtime on a simulator dataset against truth: accuracy, fill, active/passive", &RunScore},
      {"tune", "measure the laser grid's period in a capture -> the runtime options tied to it", &RunTune},
      {"rig", "inspect a rig file: validate, summarise, export .cameramodel files", &RunRig},
      {"demo", "run every stage on the embedded default rig and print the figures", &RunDemo},
  };
  return commands;
}

}  // namespace stereorig
