// The rig file: the calibration result (and the simulator's ground truth) as
// plain, versioned YAML in millimetres. docs/formats.md defines it.
//
// Round trip is lossless: doubles are written with %.17g, so
// ReadRigFile(WriteRigFile(rig)) reproduces every bit, and writing it again
// gives the same bytes.
#pragma once

#include <string>

#include "rig.h"

namespace stereorig {

// Written: 2. Read: 1 and 2 (2 adds provenance.target, the board calibrated
// with; a build that reads only 1 refuses a version 2 file by its version).
inline constexpr int kRigFileVersion = 2;

// Throws InputError naming the file and key on: a missing file, bad YAML,
// unknown or missing keys, wrong types, NaN/Inf, non-orthonormal rotations,
// an unknown lens model, the wrong number of intrinsics, an inconsistent S,
// a baseline or two modules' distance under 1 mm (typed in metres).
// With `bytes_read`, the file's bytes as parsed: read once, so that what
// is fingerprinted (stereorig check's CRC-32) is the rig that was parsed.
Rig ReadRigFile(const std::string& path, std::string* bytes_read = nullptr);
Rig ParseRigYaml(const std::string& text, const std::string& where);

std::string RigToYaml(const Rig& rig);
// Atomic: temp file and rename.
void WriteRigFile(const Rig& rig, const std::string& path);

// The shortest text that reads back as the same double (ShortestNumberText,
// number_text.h): 38.1, where %.17g wrote 38.100000000000001. For every file
// stereorig writes for people to read: rig, target, artifact, simulator
// files and exported camera models.
std::string FormatDouble(double x);
// Current UTC time as ISO 8601 ("2026-11-23T13:00:00Z"), for provenance.
std::string NowUtcIso8601();
// "stereorig <version>".
std::string ToolVersion();

}  // namespace stereorig
