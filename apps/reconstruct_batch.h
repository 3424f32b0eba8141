// `stereorig reconstruct` over many captures with one runtime: the line's
// way to run it. The rig file is read and the runtime built (rectification
// maps, ranges) once, not once per object; the next capture's images are
// read while the current one is reconstructed.
#pragma once

#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "reconstruct/runtime_options.h"

namespace stereorig {

// One output name per capture folder, unique: each folder's path (made
// absolute and normal) after the components all of them share, joined with
// '_', keeping at least the last component. "caps/0001", "caps/0002" give
// "0001", "0002"; "scenes/cup/active", "scenes/sphere/active" give
// "cup_active", "sphere_active". Throws InputError if a folder is given
// twice (also through a link: folders compared as the file system resolves
// them, ResolvedFolder) or two names collide ("a_b" and "a/b").
std::vector<std::string> BatchOutputNames(const std::vector<std::string>& capture_dirs);

struct BatchRequest {
  std::vector<std::string> capture_dirs;
  std::string out_dir;       // created if missing
  std::string mesh_format;   // "" (no mesh), "ply" or "stl"
  std::string summary_path;  // "" or the batch's JSON summary
  std::string rig_path;      // the rig file and options file read ("" if none): no output may be either
  std::string options_path;
};

// Checks every capture folder's files (CheckCaptureFiles) and the names
// before anything is written; then reconstructs each capture and writes
// out_dir/<name>.ply, <name>.json (its report) and <name>.mesh.<format>,
// each atomically, printing one line per capture. A capture whose images
// turn out bad (undecodable, wrong size or type) is reported on stderr and
// gets no output; the others go on. A module that gives no point is warned
// of and counted (reconstruct_capture.h), not failed. Returns the exit code:
// 0, or 2 when any capture was bad input. Throws InputError for bad input found before the
// first capture (nothing written then).
int ReconstructBatch(const Rig& rig, const RuntimeOptions& options, const BatchRequest& request);

}  // namespace stereorig
