// How many positions a `stereorig verify` run measured: which --cloud
// repeats an earlier one (the same file, a byte-identical copy, or a cloud
// whose fitted spheres are the earlier one's), and how
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
  // Not the same bytes, but the same measurement: its fitted spheres are
  // the earlier position's (MarkSameFits).
  bool same_fit = false;
};

// Per cloud, in order: the first earlier cloud it repeats. Byte identity is
// compared only between files of the same size (a copy under another name
// counted as a new position).
std::vector<RepeatedPosition> RepeatedPositions(const std::vector<std::string>& clouds);

// Two positions whose fitted spheres (every centre and diameter) agree
// within this are one measurement: a cloud re-saved as ASCII or big-endian
// has other bytes but fits the same, within the rounding of its
// coordinates (a float's at 200 mm is 0.02 um a point, averaged over
// thousands). A physical position is not repeated to 1 um, nor is an
// unmoved artifact measured again (the demo's sphere fits its centre to
// ~3 um).
inline constexpr double kSameFitMm = 0.001;

// Marks, in `repeated` (RepeatedPositions' answer), each position that
// repeats no earlier cloud but whose fit (fitted_mm, per position: each
// sphere's centre x, y, z and diameter, in order; empty where none was
// fitted: a plate, whose plane a position moved within it keeps, or a
// position not evaluated) agrees within kSameFitMm with an earlier distinct
// position's: that one, same_fit.
void MarkSameFits(const std::vector<std::vector<double>>& fitted_mm, std::vector<RepeatedPosition>* repeated);

}  // namespace stereorig
