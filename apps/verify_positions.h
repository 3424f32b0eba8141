// How many positions a `stereorig verify` run measured: which --cloud
// repeats an earlier one (the same file, or a byte-identical copy), and how
// many the procedure asks for. Said, not refused: a test may repeat a cloud,
// and one position still has figures worth reading; but a verdict over
// fewer positions than the procedure's is not its acceptance test.
#pragma once

#include <string>
#include <vector>

namespace stereorig {

// The positions the procedure asks for (docs/verify-and-check.md, "Running
// it"): VDI/VDE 2634-2's 7 sphere positions and 7 ball-bar orientations
// spread through the volume; the same is asked of the plate.
inline constexpr int kPositionsAsked = 7;

struct RepeatedPosition {
  int earlier = -1;        // index of the earlier --cloud it repeats; -1: none
  bool same_file = false;  // the same file (a path or a link to it); else a byte-identical copy
};

// Per cloud, in order: the first earlier cloud it repeats. Byte identity is
// compared only between files of the same size (a copy under another name
// counted as a new position).
std::vector<RepeatedPosition> RepeatedPositions(const std::vector<std::string>& clouds);

}  // namespace stereorig
