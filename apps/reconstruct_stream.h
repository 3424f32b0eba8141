// `stereorig reconstruct --capture - --out-dir OUT`: capture folders read
// from standard input, one per line, each reconstructed as soon as its line
// arrives, by one runtime built at the start. This is how a line's
// acquisition software drives the runtime one object at a time (a pipe, or
// a FIFO it writes a folder's path to once the folder is complete) without
// paying a process start and a cold first capture per object: ~0.25 s and
// ~0.13 s on the default rig, twice the warm reconstruction itself.
//
// A batch (reconstruct_batch.h) knows all its captures first and checks them
// all before writing anything; a stream cannot, so each capture is checked
// when its line comes, and a bad one (a missing camera, a folder or output
// name already used in this run, bad images, outputs that cannot be
// written) is named on stderr and gets no output, while the stream goes on.
#pragma once

#include <string>

#include "calib/core/rig.h"
#include "reconstruct/runtime_options.h"

namespace stereorig {

// A capture's output name in a stream. Without `root` (""), its folder's
// last name ("line/2026-12-06/0001", "line/2026-12-06/0001/" -> "0001"; "."
// -> the current folder's name). With it, the folder's path below `root`,
// joined with '_' (root "line": "line/2026-12-06/0001" ->
// "2026-12-06_0001"), as a batch names its folders after the part all share:
// folders numbered afresh each day keep their names apart. Paths compared
// absolute and normal as written, else (a root or a folder given through a
// link) as the file system resolves them (ResolvedFolder). Throws
// InputError(dir) for the file system's root, or a folder that is below
// `root` neither way.
std::string StreamOutputName(const std::string& dir, const std::string& root = "");

struct StreamRequest {
  std::string out_dir;       // created if missing
  std::string mesh_format;   // "" (no mesh), "ply" or "stl"
  std::string summary_path;  // "" or the run's JSON summary, written at the end of the input
  std::string rig_path;      // the rig file and options file read ("" if none): no output may be either
  std::string options_path;
  // "" or a capture reconstructed once before the first line is read, its
  // outputs not written: the first capture after a start costs more than a
  // warm one (the heap's pages faulted in, ~15 us each on this VM, the
  // worker threads started), which a line's first object would pay.
  std::string warm_up_dir;
  std::string capture_root;  // "" or the folder the captures' output names are taken below (StreamOutputName)
};

// Builds the runtime, then reads `input_fd` (standard input) to its end, or
// until SIGTERM, SIGINT or SIGHUP stops it (stream_input.h: the capture in
// progress is finished and written, no further line read, the summary
// written with `stopped_by`; a stop before the first capture returns 0 and
// writes no summary), or until stdout cannot be written (a capture's line
// lost: the stream stops after that capture, summary written with
// `output_error`, exit 2). Each line (a trailing '\r'
// dropped; blank lines skipped) names a capture folder, reconstructed and
// written as out_dir/<name>.ply, <name>.json and <name>.mesh.<format>, each
// atomically, with one line on stdout, flushed (reconstruct_capture.h). An
// output this run wrote already is never replaced: that capture is refused.
// The memory does not grow with the captures: the summary (written when the
// input ends) holds the totals and the first 1000 failed captures, not the
// reconstructed ones, which have their own reports.
// Returns the exit code: 0, or 2 when any capture failed. Throws InputError
// for bad input found before the first line is read (the options, the
// output folder, the summary's path: nothing written then) and when the
// input holds no capture folder at all.
int ReconstructStream(const Rig& rig, const RuntimeOptions& options, const StreamRequest& request, int input_fd);

}  // namespace stereorig
