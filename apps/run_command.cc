#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "calib/core/input_error.h"

namespace stereorig {

int RunCommand(const Command& command, int argc, char** argv) {
  try {
    return command.run(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a ParseError in CLI11 with exit code 0.
    if (e.get_exit_code() == 0) return kExitOk;
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, PrintableText(e.what()).c_str());
    return kExitBadInput;
  } catch (const InputError& e) {
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, PrintableText(e.what()).c_str());
    return kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the user gave that cannot be listed, read or written (a folder
    // without permission, a file where a folder should be): its message
    // names the path.
    std::fprintf(stderr, "stereorig %s: %s\n", command.name, PrintableText(e.what()).c_str());
    return kExitBadInput;
  }
}

}  // namespace stereorig
