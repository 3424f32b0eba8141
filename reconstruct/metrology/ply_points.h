// Reads the vertex positions of any PLY file: ascii or binary little/big
// endian, x/y/z of any numeric type, any other vertex properties skipped
// (lists too). The elements after the vertices are read and checked, not
// kept: a face's vertex indices must name vertices of the file, and the file
// must end where its header says. This is what `stereorig verify` needs
// from a cloud or mesh, whatever tool wrote it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace stereorig {

// The `module` of the points stereorig's hole filling adds from a fitted
// shape model (reconstruct/point_cloud.h's kFilledModule, docs/reconstruct.md's
// PLY properties): no module measured them.
inline constexpr int kPlyFilledModule = 255;

struct PlyVertices {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> module;  // each vertex's `module` property; empty when the file has none
  // Each vertex's nx, ny, nz (a stereorig cloud's face the camera of the
  // module that measured the point: docs/formats.md); empty when the file
  // has none. As written: not normalised, a zero one is no direction.
  std::vector<Eigen::Vector3d> normals;
  long long faces = 0;  // the count of its `face` element: > 0 for a mesh
};

// Throws InputError naming the file on a missing file, a folder, a malformed header, no
// x/y/z, some of nx/ny/nz but not all, a `module` that is not uchar, a
// truncated body, non-finite coordinates or normals, a face of fewer than 3
// vertices or naming one the file does not hold, or data after the last
// element; on a file named .stl
// that is not PLY, it says that an STL mesh holds no module and names the
// cloud to give instead.
PlyVertices ReadPlyVertices(const std::string& path);
std::vector<Eigen::Vector3d> ReadPlyPoints(const std::string& path);  // ReadPlyVertices(path).points

// The measured points of a cloud: the vertices whose module is not
// kPlyFilledModule (all of them when the file has no `module`), and how many
// filled ones were left out.
struct MeasuredPoints {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;  // parallel to points; empty when the file has none
  int filled_skipped = 0;
  // Non-empty for a mesh (faces) without `module`: why every vertex was
  // taken as measured, for a note. A mesh from another tool has none; a
  // stereorig mesh written before its vertices kept their module may hold
  // hole filling's, which no reader can tell apart.
  std::string note;
};
MeasuredPoints ReadMeasuredPlyPoints(const std::string& path);

}  // namespace stereorig
