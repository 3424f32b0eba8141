// Test helper: one scene of the default rig, rendered by the simulator into
// a fresh folder (no calibration captures: a few seconds).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

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

}  // namespace stereorig::testing
