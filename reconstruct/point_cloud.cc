#include "reconstruct/point_cloud.h"

namespace stereorig {

void PointCloud::Reserve(size_t points) {
  xyz_mm.reserve(points);
  normal.reserve(points);
  intensity.reserve(points);
  module.reserve(points);
  confidence.reserve(points);
}

void PointCloud::Resize(size_t points) {
  xyz_mm.resize(points);
  normal.resize(points);
  intensity.resize(points);
  module.resize(points);
  confidence.resize(points);
}

void PointCloud::Append(const PointCloud& o) {
  xyz_mm.insert(xyz_mm.end(), o.xyz_mm.begin(), o.xyz_mm.end());
  normal.insert(normal.end(), o.normal.begin(), o.normal.end());
  intensity.insert(intensity.end(), o.intensity.begin(), o.intensity.end());
  module.insert(module.end(), o.module.begin(), o.module.end());
  confidence.insert(confidence.end(), o.confidence.begin(), o.confidence.end());
}

void Mesh::Reserve(size_t num_vertices, size_t num_triangles) {
  vertices.Reserve(num_vertices);
  triangles.reserve(num_triangles);
}

void Mesh::Append(const Mesh& o) {
  const int offset = int(vertices.size());
  vertices.Append(o.vertices);
  for (const Eigen::Vector3i& t : o.triangles) triangles.push_back(t + Eigen::Vector3i::Constant(offset));
}

}  // namespace stereorig
