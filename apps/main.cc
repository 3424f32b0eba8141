// stereorig: one binary, table-registered subcommands (apps/commands.cc).
#include <cstdio>
#include <cstring>
#include <string>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "reconstruct/heap_retention.h"

namespace {

void PrintUsage(FILE* out) {
  std::fprintf(out,
               "stereorig: calibrate a multi-module active stereo rig and reconstruct one-shot captures.\n\n"
               "Usage: stereorig <command> [options]    (stereorig <command> --help for each)\n\n"
               "Commands:\n");
  for (const auto& c : stereorig::Commands()) std::fprintf(out, "  %-12s %s\n", c.name, c.summary);
  std::fprintf(out,
               "\nExit codes: 0 ok; 1 a check that ran and failed (verify, check), or a demo step that did not exit "
               "as expected; 2 bad usage or input.\n"
               "Start with:  stereorig demo --out /tmp/stereorig-demo\n");
}

}  // namespace

int main(int argc, char** argv) {
  // Capture after capture (reconstruct, bench, score, demo) the runtime
  // reuses its freed maps instead of faulting them in again (heap_retention.h).
  stereorig::RetainFreedHeapMemory();
  // Every exit goes through ExitCodeWithStdout: a run whose stdout lost what
  // it printed (a full disk, /dev/full) exits 2, not 0 (cli_util.h). Here,
  // not in RunCommand, so that --help and --version are covered and demo's
  // in-process steps (RunCommand each) do not each report it.
  if (argc < 2) {
    PrintUsage(stderr);
    return stereorig::kExitBadInput;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintUsage(stdout);
    return stereorig::ExitCodeWithStdout(stereorig::kExitOk, "stereorig");
  }
  if (name == "--version") {
    std::printf("stereorig %s\n", STEREORIG_VERSION);
    return stereorig::ExitCodeWithStdout(stereorig::kExitOk, "stereorig");
  }
  for (const auto& c : stereorig::Commands()) {
    if (name == c.name)
      return stereorig::ExitCodeWithStdout(stereorig::RunCommand(c, argc - 1, argv + 1), "stereorig " + name);
  }
  std::fprintf(stderr, "stereorig: unknown command '%s' (stereorig --help lists them)\n",
               stereorig::PrintableText(name).c_str());
  return stereorig::kExitBadInput;
}
