#include "reconstruct/point_cloud.h"

#include <limits>

#include "calib/core/input_error.h"

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

void Mesh::Append(const Mesh& o, size_t vertex_offset) {
  STEREORIG_CHECK(vertex_offset <= size_t(std::numeric_limits<int>::max()));
  const Eigen::Vector3i offset = Eigen::Vector3i::Constant(int(vertex_offset));
  for (const Eigen::Vector3i& t : o.triangles) triangles.push_back(t + offset);
}

void CheckMeshOver(const PointCloud& vertices, const Mesh& mesh) {
  const int n = int(vertices.size());
  for (const Eigen::Vector3i& t : mesh.triangles) STEREORIG_CHECK(t.minCoeff() >= 0 && t.maxCoeff() < n);
}

}  // namespace stereorig
