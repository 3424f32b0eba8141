#include "apps/cli_util.h"

#include <cstdio>

#include "apps/command.h"

namespace stereorig {

std::optional<int> ParseArgs(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", app.get_name().c_str(), e.what());
    return kExitBadInput;
  }
  return std::nullopt;
}

int NotBuiltYet(const char* name, const char* what, int argc, char** argv) {
  CLI::App app{std::string(what) + "\n\nNOT BUILT YET: this subcommand is reserved; a later release fills it in.",
               std::string("stereorig ") + name};
  app.allow_extras();
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  std::fprintf(stderr, "stereorig %s: not built yet in this release (see stereorig %s --help)\n", name, name);
  return kExitBadInput;
}

}  // namespace stereorig
