// The folder `stereorig demo --out` writes into, judged before any step:
// the demo writes a dozen files and folders there by fixed names (rig.yaml,
// dataset/, cup_active.ply, ...), replacing any of those names already
// there. So it writes only into a folder that is missing, empty, or an
// earlier demo's, as `stereorig simulate --out` replaces only an earlier
// dataset (datasets/simulate.h, CheckReplaceableOut): a folder of the
// user's (notes, their own rig.yaml) is refused, naming what is in it.
#pragma once

#include <string>

namespace stereorig {

// Whether `name` (a file or folder directly in --out) is one the demo writes.
bool DemoWrites(const std::string& name);

// Throws InputError naming `out` (as typed) unless the demo may write into
// it: it does not exist, is empty, or is an earlier demo's folder: its
// dataset/ an earlier dataset simulate may replace, and nothing in it but
// what the demo writes (DemoWrites).
void CheckDemoOut(const std::string& out);

}  // namespace stereorig
