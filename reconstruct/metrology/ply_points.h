// Reads the vertex positions of any PLY file: ascii or binary little/big
// endian, x/y/z of any numeric type, any other vertex properties skipped
// (lists too), other elements ignored after the vertices. This is what
// `stereorig verify` needs from a cloud, whatever tool wrote it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

// Throws InputError naming the file on a missing file, a malformed header, no
// x/y/z, a truncated body or non-finite coordinates.
std::vector<Eigen::Vector3d> ReadPlyPoints(const std::string& path);

}  // namespace stereorig
