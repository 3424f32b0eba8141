// Runs the real `stereorig` binary for CLI contract tests.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace stereorig::testing {

inline const std::string kBin = std::string(STEREORIG_BINARY_DIR) + "/stereorig";

struct Result {
  int code;
  std::string out, err;
};

inline Result RunCli(const std::string& args) {
  const std::string dir = ::testing::TempDir();
  // Per process: several checkouts' test suites may run at once on one machine.
  const std::string tag = std::to_string(getpid());
  const std::string o = dir + "/cli_out_" + tag + ".txt", e = dir + "/cli_err_" + tag + ".txt";
  const int status = std::system((kBin + " " + args + " >" + o + " 2>" + e).c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(o), slurp(e)};
}

inline int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace stereorig::testing
