#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "apps/command.h"
#include "calib/core/input_error.h"

namespace stereorig {

int RunCommand(const Command& command, int argc, char** argv) {
  try {
    return command.run(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a ParseError in CLI11 with exit code 0.
    if (e.get_exit_code() == 0) return kExitOk;
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, e.what());
    return kExitBadInput;
  } catch (const InputError& e) {
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, e.what());
    return kExitBadInput;
  }
}

}  // namespace stereorig
