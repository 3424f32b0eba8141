// What `stereorig demo` requires of its steps beyond their exit codes, and
// the note saying which binary its printed `$ stereorig ...` lines mean. The
// README promises an exit 0 only when the check names the bumped camera:
// the bumped night's exit code (1, recalibrate) alone also passed a night
// that named another camera, or a module only.
#pragma once

#include <string>

namespace stereorig {

// "" when the check report at `report_path` (docs/verify-and-check.md, "The
// report") says `recalibrate` and names camera `bumped_camera` alone
// (flagged_cameras [bumped_camera], flagged_modules []), as the check study
// counts a bump named (tests/check_study.sh); else what it says instead,
// e.g. "its report names cameras [3] and modules [], expected camera 1
// alone", or why it cannot be read.
std::string BumpedNightSurprise(const std::string& report_path, int bumped_camera);

// "" when `self_exe` (the running binary) is the `stereorig` a shell finds
// through `path_env` (PATH's value: the first executable file named
// stereorig in its folders, an empty entry the current folder), so the
// printed lines run it as they are; else one line naming `self_exe` as the
// binary they mean, and the one on PATH or that there is none. A null
// `path_env` is an empty PATH.
std::string BinaryNote(const std::string& self_exe, const char* path_env);

}  // namespace stereorig
