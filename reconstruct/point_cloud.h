// The runtime's outputs: a point cloud with per-point attributes and a
// triangle mesh over its points, in the reference frame (module 0), mm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace stereorig {

// Module index of points that no module saw: they come from the shape model
// (hole filling).
inline constexpr uint8_t kFilledModule = 255;

struct PointCloud {
  std::vector<Eigen::Vector3f> xyz_mm;
  std::vector<Eigen::Vector3f> normal;  // unit, towards the camera that saw the point
  std::vector<uint8_t> intensity;       // grey level of the rectified left image
  std::vector<uint8_t> module;          // module index, or kFilledModule
  std::vector<float> confidence;        // [0, 1]
  size_t size() const { return xyz_mm.size(); }
  void Reserve(size_t points);  // capacity for `points` in every field
  void Resize(size_t points);   // `points` in every field; new ones uninitialised (Eigen) or zero
  void Append(const PointCloud& other);
};

// A triangle mesh over a point cloud: its vertices are the cloud's points,
// so a mesh is only its triangles, and is written with the cloud it indexes
// (EncodeMesh(cloud, mesh, path), ply_io.h). The mesh PLY so keeps each
// vertex's module: `stereorig verify` must tell hole filling's vertices
// (kFilledModule) from measured ones in a mesh as in a cloud. Who holds a
// Mesh holds the cloud beside it (Reconstruction::cloud) and keeps the two
// consistent: a point removed reindexes the triangles (CheckMeshOver).
struct Mesh {
  std::vector<Eigen::Vector3i> triangles;  // indices into the cloud, counter-clockwise seen from outside
  // Appends `other`'s triangles, whose indices are into a cloud appended
  // to this mesh's at `vertex_offset` (its size before PointCloud::Append;
  // the caller reserves the joined triangles).
  void Append(const Mesh& other, size_t vertex_offset);
};

// A triangle indexing no point of `vertices` is a programming error (the
// cloud and the mesh went out of step): STEREORIG_CHECK fails on it.
void CheckMeshOver(const PointCloud& vertices, const Mesh& mesh);

// Removes the points i with drop[i] != 0 (drop: one entry per point) from
// *cloud, keeping the others in order, and from the mesh over it: a
// triangle with a removed vertex goes, the others take their vertices' new
// indices.
void RemovePoints(const std::vector<uint8_t>& drop, PointCloud* cloud, Mesh* mesh);

}  // namespace stereorig
