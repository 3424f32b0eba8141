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
  // Per process and call: ctest runs test cases in parallel processes that
  // share TempDir().
  static int calls = 0;
  const std::string stem = ::testing::TempDir() + "/cli_" + std::to_string(getpid()) + "_" + std::to_string(calls++);
  const std::string o = stem + "_out.txt", e = stem + "_err.txt";
  const int status = std::system((kBin + " " + args + " >" + o + " 2>" + e).c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  Result r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(o), slurp(e)};
  std::remove(o.c_str());
  std::remove(e.c_str());
  return r;
}

// A path where no file can be created, not even by root: a name in /proc,
// whose entries are the kernel's. Every user is refused by the commands'
// up-front checks, before any work (apps/output_paths.h creates and removes
// a file there: access(2) alone let root through, and the output failed
// only late, after the others' temporary files were written).
inline std::string UnwritablePath(const std::string& name) { return "/proc/stereorig-" + name; }

inline int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace stereorig::testing
