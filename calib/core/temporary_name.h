// The name of a temporary file or folder written beside an output and
// renamed over it at the end (calib/core/atomic_file.h, datasets/simulate.cc):
// the output's own name, tagged so that it is hidden and unique. An output's
// name may be as long as the file system allows, so the tagged name would not
// always fit; the part copied from the output's name is shortened instead.
#pragma once

#include <cstddef>
#include <string>

namespace stereorig {

// The longest name the file system takes, in bytes: NAME_MAX, 255 on the
// file systems Linux writes (ext4, xfs, btrfs, tmpfs).
inline constexpr size_t kMaxNameBytes = 255;

// prefix + name + suffix, at most kMaxNameBytes bytes: `prefix` and `suffix`
// whole (the pid and counter in them keep the name unique; their total must
// leave room, a programming error otherwise), `name` cut where it is too
// long. The cut falls before name's extension (writers such as cv::imwrite
// pick the format by it; an extension longer than half the room is not
// kept apart) and never inside a UTF-8 character.
std::string TemporaryName(const std::string& prefix, const std::string& name, const std::string& suffix = "");

}  // namespace stereorig
