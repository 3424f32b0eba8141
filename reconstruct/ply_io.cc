#include "reconstruct/ply_io.h"

#include <Eigen/Geometry>
#include <bit>
#include <cstdint>
#include <cstring>

#include "calib/core/atomic_file.h"
#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"
#include "reconstruct/metrology/ply_points.h"

namespace stereorig {
namespace {

// The project targets little-endian hosts (x86-64, arm64); PLY and STL here
// are little-endian, so values are copied as they are in memory.
static_assert(std::endian::native == std::endian::little, "little-endian host expected");
// `stereorig verify` leaves the filled points out by this module.
static_assert(kPlyFilledModule == kFilledModule, "verify must know hole filling's module");

template <typename T>
void Put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

// The vertex element's header lines and records, the same in the cloud and
// the mesh PLY: a mesh's vertices keep their module (255: hole filling's),
// so `stereorig verify` skips the filled ones in either file.
std::string VertexHeader(const PointCloud& c) {
  return "element vertex " + std::to_string(c.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar intensity\n"
         "property float nx\nproperty float ny\nproperty float nz\nproperty uchar module\n"
         "property float confidence\n";
}

void PutVertices(const PointCloud& c, std::string& out) {
  out.reserve(out.size() + c.size() * 34);
  for (size_t i = 0; i < c.size(); ++i) {
    for (int k = 0; k < 3; ++k) Put(out, c.xyz_mm[i][k]);
    Put(out, c.intensity[i]);
    for (int k = 0; k < 3; ++k) Put(out, c.normal[i][k]);
    Put(out, c.module[i]);
    Put(out, c.confidence[i]);
  }
}

}  // namespace

std::string EncodeCloudPly(const PointCloud& c) {
  std::string out =
      "ply\nformat binary_little_endian 1.0\ncomment stereorig point cloud, reference frame (module 0), mm\n" +
      VertexHeader(c) + "end_header\n";
  PutVertices(c, out);
  return out;
}

void WriteCloudPly(const PointCloud& cloud, const std::string& path) {
  CheckCloudPath(path);
  WriteFileAtomically(path, EncodeCloudPly(cloud));
}

void CheckCloudPath(const std::string& path) {
  if (!EndsWithIgnoringCase(path, ".ply"))
    throw InputError(path, "cloud output must end in .ply (it is written as binary PLY)");
}

void CheckMeshPath(const std::string& path) {
  if (!EndsWithIgnoringCase(path, ".ply") && !EndsWithIgnoringCase(path, ".stl"))
    throw InputError(path, "mesh output must end in .ply or .stl");
}

std::string EncodeMesh(const PointCloud& vertices, const Mesh& m, const std::string& path) {
  CheckMeshPath(path);
  CheckMeshOver(vertices, m);
  // Reserved whole: a mesh of the cup is ~25 MB, and growing the string
  // by doubling copied it and faulted fresh pages in at every step, for
  // each capture of a line (+0.35-0.5 s a capture with --mesh-format).
  std::string out;
  if (EndsWithIgnoringCase(path, ".stl")) {
    out.reserve(84 + 50 * m.triangles.size());  // header, count, 50 bytes a triangle
    out.assign(80, ' ');
    out.replace(0, 40, "stereorig mesh, reference frame, mm     ");
    Put(out, uint32_t(m.triangles.size()));
    const std::vector<Eigen::Vector3f>& v_mm = vertices.xyz_mm;
    for (const Eigen::Vector3i& t : m.triangles) {
      const Eigen::Vector3f a = v_mm[t[0]], b = v_mm[t[1]], c = v_mm[t[2]];
      Eigen::Vector3f n = (b - a).cross(c - a);
      if (n.norm() > 0) n.normalize();
      for (int k = 0; k < 3; ++k) Put(out, n[k]);
      for (const Eigen::Vector3f& v : {a, b, c})
        for (int k = 0; k < 3; ++k) Put(out, v[k]);
      Put(out, uint16_t(0));
    }
  } else {
    out = "ply\nformat binary_little_endian 1.0\ncomment stereorig mesh, reference frame (module 0), mm\n" +
          VertexHeader(vertices) + "element face " + std::to_string(m.triangles.size()) +
          "\nproperty list uchar int vertex_indices\nend_header\n";
    out.reserve(out.size() + 34 * vertices.size() + 13 * m.triangles.size());  // PutVertices' 34, 1 + 3 x 4 a face
    PutVertices(vertices, out);
    for (const Eigen::Vector3i& t : m.triangles) {
      Put(out, uint8_t(3));
      for (int k = 0; k < 3; ++k) Put(out, int32_t(t[k]));
    }
  }
  return out;
}

void WriteMesh(const PointCloud& vertices, const Mesh& m, const std::string& path) {
  WriteFileAtomically(path, EncodeMesh(vertices, m, path));
}

}  // namespace stereorig
