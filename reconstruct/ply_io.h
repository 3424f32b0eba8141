// Writers for the runtime's outputs (docs/formats.md, docs/reconstruct.md).
//
// Cloud PLY, binary little-endian, one vertex element with the properties
//   float x, y, z (mm); uchar intensity; float nx, ny, nz; uchar module;
//   float confidence.
// Mesh (triangles over a cloud's points, point_cloud.h): PLY (the cloud's
// vertex element, byte for byte the cloud PLY's records, then face list
// uchar/int vertex_indices into it) or binary STL (triangles only: no
// module, so hole filling's vertices cannot be told apart), chosen by the
// extension. All writes are atomic.
#pragma once

#include <string>

#include "reconstruct/point_cloud.h"

namespace stereorig {

std::string EncodeCloudPly(const PointCloud& cloud);
// Binary PLY; InputError unless `path` ends in .ply (CheckCloudPath).
// Suffixes here are read without case (.PLY, .Stl: file_suffix.h).
void WriteCloudPly(const PointCloud& cloud, const std::string& path);
// Throws InputError unless `path` ends in .ply: a cloud is always PLY, and
// "cloud.xyz" or "cloud.pcd" would otherwise get PLY bytes a reader of that
// format cannot parse. Commands call it before any work.
void CheckCloudPath(const std::string& path);
// `mesh`'s triangles index `vertices` (a triangle out of its range is a
// programming error: CheckMeshOver). `path` ending in .stl -> binary STL,
// .ply -> binary PLY; else InputError.
void WriteMesh(const PointCloud& vertices, const Mesh& mesh, const std::string& path);
// The bytes WriteMesh writes to `path` (its suffix picks the format).
std::string EncodeMesh(const PointCloud& vertices, const Mesh& mesh, const std::string& path);
// Throws InputError unless `path` ends in .ply or .stl.
void CheckMeshPath(const std::string& path);

}  // namespace stereorig
