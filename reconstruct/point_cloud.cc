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

void RemovePoints(const std::vector<uint8_t>& drop, PointCloud* cloud, Mesh* mesh) {
  STEREORIG_CHECK(drop.size() == cloud->size());
  CheckMeshOver(*cloud, *mesh);  // new_index is read at every vertex of every triangle
  std::vector<int> new_index(cloud->size(), -1);
  PointCloud kept;
  kept.Reserve(cloud->size());
  for (size_t i = 0; i < cloud->size(); ++i) {
    if (drop[i]) continue;
    new_index[i] = int(kept.size());
    kept.xyz_mm.push_back(cloud->xyz_mm[i]);
    kept.normal.push_back(cloud->normal[i]);
    kept.intensity.push_back(cloud->intensity[i]);
    kept.module.push_back(cloud->module[i]);
    kept.confidence.push_back(cloud->confidence[i]);
  }
  *cloud = std::move(kept);
  size_t n = 0;
  for (const Eigen::Vector3i& tri : mesh->triangles) {
    const Eigen::Vector3i m(new_index[tri[0]], new_index[tri[1]], new_index[tri[2]]);
    if (m.minCoeff() >= 0) mesh->triangles[n++] = m;
  }
  mesh->triangles.resize(n);
}

}  // namespace stereorig
