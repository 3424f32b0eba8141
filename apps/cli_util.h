// Shared pieces of the subcommands: argument parsing with the project's exit
// codes, and the "not built yet" answer of subcommands still to come.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace stereorig {

// Parses argv into `app`. Returns an exit code when the command must stop now
// (0 after printing --help to stdout; 2 after one line on stderr for a usage
// error), or std::nullopt when it should run.
std::optional<int> ParseArgs(CLI::App& app, int argc, char** argv);

// For subcommands a later issue fills in: prints what it will do and exits 2.
int NotBuiltYet(const char* name, const char* what, int argc, char** argv);

}  // namespace stereorig
