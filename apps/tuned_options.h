// The runtime options file `stereorig tune` writes: the options file it
// started from (or none: the built-in defaults) with the keys tied to the
// grid's period set under `match:` (grid_period_options.h), after a comment
// header saying where they came from.
#pragma once

#include <string>
#include <vector>

#include "reconstruct/grid_period_options.h"

namespace stereorig {

// base_text: the --options file's text (already parsed and checked: it is
// read once, so a pipe works), or empty. Its keys and their order are kept,
// its comments are not (yaml-cpp does not keep them). Each line of `header`
// becomes a "# " comment line. Whole values are written as integers.
std::string TunedOptionsYaml(const std::string& base_text, const std::vector<GridPeriodKey>& keys,
                             const std::string& header);

// Throws InputError(path) unless it ends in .yaml or .yml (any case): an
// options file, not a cloud or image typed in the wrong place.
void CheckOptionsPath(const std::string& path);

}  // namespace stereorig
