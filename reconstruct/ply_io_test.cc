// The mesh writer: a mesh is triangles over a cloud's points (point_cloud.h),
// written from the cloud and the triangles. The PLY holds the cloud's vertex
// records as the cloud PLY has them and the faces' indices into them; the
// STL each triangle's corners from the cloud; a triangle indexing no point
// of the cloud is refused as the programming error it is; removing points
// renumbers the triangles over those kept.
#include "reconstruct/ply_io.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

namespace stereorig {
namespace {

// Four points with distinct values in every field, module 255 last (a
// filled point), so a field written from the wrong point or left out shows.
PointCloud FourPoints() {
  PointCloud c;
  for (int i = 0; i < 4; ++i) {
    c.xyz_mm.emplace_back(1.5f * i, -2.0f + i, 200.0f + 0.25f * i);
    c.normal.push_back(Eigen::Vector3f(0.1f * i, 0.2f, -1.0f).normalized());
    c.intensity.push_back(uint8_t(10 + i));
    c.module.push_back(i == 3 ? kFilledModule : uint8_t(i % 2));
    c.confidence.push_back(0.2f * i);
  }
  return c;
}

template <typename T>
T Get(const std::string& bytes, size_t* at) {
  T v;
  std::memcpy(&v, bytes.data() + *at, sizeof(T));
  *at += sizeof(T);
  return v;
}

std::string Body(const std::string& ply) { return ply.substr(ply.find("end_header\n") + 11); }

TEST(MeshPly, HoldsTheCloudsVertexRecordsThenTheFacesIndicesIntoThem) {
  const PointCloud cloud = FourPoints();
  Mesh mesh;
  mesh.triangles = {Eigen::Vector3i(0, 2, 1), Eigen::Vector3i(1, 2, 3)};
  const std::string ply = EncodeMesh(cloud, mesh, "m.ply");
  EXPECT_NE(ply.find("element vertex 4\n"), std::string::npos) << ply.substr(0, 400);
  EXPECT_NE(ply.find("element face 2\nproperty list uchar int vertex_indices\nend_header\n"), std::string::npos);
  const std::string cloud_body = Body(EncodeCloudPly(cloud)), mesh_body = Body(ply);
  ASSERT_EQ(mesh_body.size(), cloud_body.size() + 2 * (1 + 3 * 4));
  EXPECT_EQ(mesh_body.substr(0, cloud_body.size()), cloud_body);  // every field of every point, in the cloud's order
  size_t at = cloud_body.size();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    EXPECT_EQ(Get<uint8_t>(mesh_body, &at), 3);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(Get<int32_t>(mesh_body, &at), t[k]);
  }
}

TEST(MeshStl, HoldsEachTrianglesCornersFromTheCloud) {
  const PointCloud cloud = FourPoints();
  Mesh mesh;
  mesh.triangles = {Eigen::Vector3i(3, 0, 2)};
  const std::string stl = EncodeMesh(cloud, mesh, "m.STL");
  ASSERT_EQ(stl.size(), 84u + 50u);
  size_t at = 80;
  EXPECT_EQ(Get<uint32_t>(stl, &at), 1u);
  at += 12;  // the facet normal
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(Get<float>(stl, &at), cloud.xyz_mm[mesh.triangles[0][k]][j]) << k << j;
}

TEST(MeshWriterDeathTest, ATriangleOutOfTheCloudsRangeIsAnInternalError) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");  // other tests of this binary start thread pools
  const PointCloud cloud = FourPoints();
  Mesh past_the_end, negative;
  past_the_end.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(1, 2, 4)};
  negative.triangles = {Eigen::Vector3i(-1, 1, 2)};
  for (const char* path : {"m.ply", "m.stl"}) {
    EXPECT_DEATH(EncodeMesh(cloud, past_the_end, path), "internal check failed") << path;
    EXPECT_DEATH(EncodeMesh(cloud, negative, path), "internal check failed") << path;
  }
}

TEST(Mesh, AppendOffsetsTheTrianglesByWhereTheirCloudBeginsInTheJoinedOne) {
  PointCloud joined = FourPoints();
  Mesh mesh;
  mesh.triangles = {Eigen::Vector3i(0, 1, 2)};
  const PointCloud second = FourPoints();
  Mesh second_mesh;
  second_mesh.triangles = {Eigen::Vector3i(1, 3, 2)};
  const size_t offset = joined.size();
  joined.Append(second);
  mesh.Append(second_mesh, offset);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(5, 7, 6));
  CheckMeshOver(joined, mesh);  // in range: no abort
}

// The free-space test removes a module's refuted points (runtime.cc,
// RemoveRefuted): the others keep their order and fields, a triangle with a
// removed vertex goes, the rest are renumbered onto the kept points.
TEST(Mesh, RemovingPointsRenumbersTheTrianglesOverThoseKept) {
  PointCloud cloud = FourPoints();
  const PointCloud before = cloud;
  Mesh mesh;
  mesh.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3), Eigen::Vector3i(2, 3, 0)};
  RemovePoints({0, 1, 0, 0}, &cloud, &mesh);  // point 1 goes: 0, 2, 3 become 0, 1, 2
  ASSERT_EQ(cloud.size(), 3u);
  const int from[3] = {0, 2, 3};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(cloud.xyz_mm[i], before.xyz_mm[from[i]]) << i;
    EXPECT_EQ(cloud.normal[i], before.normal[from[i]]) << i;
    EXPECT_EQ(cloud.intensity[i], before.intensity[from[i]]) << i;
    EXPECT_EQ(cloud.module[i], before.module[from[i]]) << i;
    EXPECT_EQ(cloud.confidence[i], before.confidence[from[i]]) << i;
  }
  ASSERT_EQ(mesh.triangles.size(), 2u);  // (0, 1, 2) held point 1
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(1, 2, 0));
  CheckMeshOver(cloud, mesh);
  RemovePoints({1, 1, 1}, &cloud, &mesh);
  EXPECT_EQ(cloud.size(), 0u);
  EXPECT_TRUE(mesh.triangles.empty());
}

}  // namespace
}  // namespace stereorig
