// Helpers of the simulate CLI tests: run the stereorig binary, read files.
#pragma once

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/cli_runner.h"

namespace sim_cli {

namespace fs = std::filesystem;
using stereorig::testing::Lines;
using stereorig::testing::Result;
using stereorig::testing::RunCli;

std::string Slurp(const std::string& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace sim_cli
