// The table of `stereorig` subcommands. Each RunX is thin: parse flags into
// an options struct, validate, call the library, write the output.
#pragma once

#include <string>
#include <vector>

namespace stereorig {

// Exit codes shared by every subcommand (docs/formats.md, "CLI").
inline constexpr int kExitOk = 0;
inline constexpr int kExitCheckFailed = 1;  // a check ran and failed (verify, check)
inline constexpr int kExitBadInput = 2;     // bad usage or bad input

struct Command {
  const char* name;
  const char* summary;  // one line, for `stereorig --help`
  // argv[0] is "stereorig <name>". Returns an exit code; may throw
  // InputError (-> exit 2).
  int (*run)(int argc, char** argv);
};

const std::vector<Command>& Commands();

// Runs a subcommand with the shared error handling: InputError and CLI11
// parse errors print one line on stderr and return 2.
int RunCommand(const Command& command, int argc, char** argv);

}  // namespace stereorig
