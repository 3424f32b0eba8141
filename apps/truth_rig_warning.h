// The warning of `score` and `bench` run without --rig: they then reconstruct
// with the simulator's truth rig, which no line has; issue 5's figures are
// the calibrated rig's (docs/reconstruct.md, "Commands"). A warning, so on
// stderr: stdout carries the results.
#pragma once

#include <string>

namespace stereorig {

// Prints one line on stderr naming `command` and `truth_rig` (the truth rig
// file read, or what stands for it) and how to score the calibrated rig.
// Called once the figures are out: last, where it is read, and never before
// a refusal (which stays one line).
void WarnOfTruthRig(const std::string& command, const std::string& truth_rig);

}  // namespace stereorig
