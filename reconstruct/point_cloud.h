// The runtime's outputs: a point cloud with per-point attributes and a
// triangle mesh, both in the reference frame (module 0), mm.
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

// The vertices carry the cloud's per-point fields, so a mesh file keeps each
// vertex's module: `stereorig verify` must tell hole filling's vertices
// (kFilledModule) from measured ones in a mesh as in a cloud.
struct Mesh {
  PointCloud vertices;
  std::vector<Eigen::Vector3i> triangles;  // indices into vertices, counter-clockwise seen from outside
  void Reserve(size_t vertices, size_t triangles);
  void Append(const Mesh& other);
};

}  // namespace stereorig
