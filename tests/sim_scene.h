// Test helper: one scene of the default rig, rendered by the simulator into
// a fresh folder (no calibration captures: a few seconds).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <vector>

#include "calib/core/rig.h"
#include "datasets/default_rig.h"
#include "datasets/simulate.h"

namespace stereorig::testing {

// Returns the dataset folder, TempDir()/NAME_PID (the caller removes it).
inline std::string SimulateOneScene(const std::string& scene, uint64_t seed, const std::string& name) {
  const std::string dir = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  SimSpec spec = DefaultSimSpec();
  spec.scenes.names = {scene};
  SimulateOptions o;
  o.out_dir = dir;
  o.seed = seed;
  o.calibration_captures = 0;
  Simulate(spec, o);
  return dir;
}

// The default rig with its cameras relabelled, 2 3 0 1: module 0 pairs
// cameras 2 and 3, module 1 cameras 0 and 1 (another layout's rig, for the
// commands that judge module m against the truth rig's module m).
inline Rig DefaultRigInAnotherLayout() {
  const SimulatedRig sim = MakeDefaultRig();
  std::vector<Camera> cameras;
  std::vector<std::string> names;
  for (int k : {2, 3, 0, 1}) {
    cameras.push_back(sim.rig.cameras()[k]);
    names.push_back(sim.rig.camera_names()[k]);
  }
  std::vector<StereoModule> modules = sim.rig.modules();
  modules[0].left_camera = 2, modules[0].right_camera = 3;
  modules[1].left_camera = 0, modules[1].right_camera = 1;
  return Rig(cameras, names, modules, sim.rig.S(), "test");
}

}  // namespace stereorig::testing
