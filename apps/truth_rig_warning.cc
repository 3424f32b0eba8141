#include "apps/truth_rig_warning.h"

#include <cstdio>

#include "apps/cli_util.h"

namespace stereorig {

void WarnOfTruthRig(const std::string& command, const std::string& truth_rig) {
  FlushStdout();  // after the figures, also where both streams go to one pipe
  std::fprintf(stderr,
               "%s: warning: no --rig: the figures above are the TRUTH rig's (%s); a line runs with its calibrated "
               "one: give --rig with the rig file from stereorig calibrate\n",
               command.c_str(), truth_rig.c_str());
}

}  // namespace stereorig
