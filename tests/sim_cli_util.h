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

namespace sim_cli {

namespace fs = std::filesystem;
const std::string kBin = std::string(STEREORIG_BINARY_DIR) + "/stereorig";

struct Result {
  int code;
  std::string out, err;
};

std::string Slurp(const std::string& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

Result RunCli(const std::string& args) {
  const std::string dir = ::testing::TempDir();
  const std::string o = dir + "/sim_cli_out.txt", e = dir + "/sim_cli_err.txt";
  const int status = std::system((kBin + " " + args + " >" + o + " 2>" + e).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(o), Slurp(e)};
}

int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace sim_cli
