// The printable target: an SVG of one or both faces at true scale.
//
// Units are millimetres throughout: the root element says width="..mm"
// height="..mm" and its viewBox spans the same numbers, so one user unit is
// one millimetre at 100 % print scale. Each face is drawn in its own face
// frame as seen by whoever looks at that face (docs/targets.md tells how to
// mount the two prints back to back), with its plate outline (the cut line),
// its name, and markers outside the plate at corner 0's row and column with
// the x and y directions. A 100 mm scale bar lets the user check the print.
#pragma once

#include <string>

#include "targets/target.h"

namespace stereorig {

enum class SvgFaces { kBoth, kFront, kBack };

struct BoardSvgOptions {
  SvgFaces faces = SvgFaces::kBoth;  // which faces to draw; default both, side by side
  double page_margin_mm = 10.0;      // white border around everything; default 10
  double face_gap_mm = 20.0;         // between the two plates; default 20
  double scale_bar_mm = 100.0;       // length of the check bar; default 100
  void Check() const;                // throws InputError naming the bad field
};

struct BoardSvg {
  std::string text;     // the SVG document
  double width_mm = 0;  // page size
  double height_mm = 0;
};

// Throws InputError if `options` asks for the back face of a plain board.
BoardSvg MakeBoardSvg(const Target& target, const BoardSvgOptions& options = {});

}  // namespace stereorig
