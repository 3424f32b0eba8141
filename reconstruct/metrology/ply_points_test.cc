#include "reconstruct/metrology/ply_points.h"

#include <gtest/gtest.h>

#include <fstream>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

TEST(PlyPoints, ReadsAsciiAndBinaryWithExtraProperties) {
  const std::string dir = ::testing::TempDir();
  {
    std::ofstream f(dir + "/a.ply");
    f << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
         "property uchar intensity\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "1 2 3 200\n-4.5 5 6e1 7\n3 0 1 1\n";
  }
  auto p = ReadPlyPoints(dir + "/a.ply");
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1], Eigen::Vector3d(-4.5, 5, 60));
  {
    std::ofstream f(dir + "/b.ply", std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty uchar module\nproperty double x\n"
         "property double y\nproperty double z\nend_header\n";
    for (int i = 0; i < 2; ++i) {
      const unsigned char m = 1;
      const double xyz[3] = {0.1 * i, 1.0 / 3.0, -7.25};
      f.write(reinterpret_cast<const char*>(&m), 1);
      f.write(reinterpret_cast<const char*>(xyz), sizeof xyz);
    }
  }
  p = ReadPlyPoints(dir + "/b.ply");
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1], Eigen::Vector3d(0.1, 1.0 / 3.0, -7.25));
}

TEST(PlyPoints, MeasuredPointsLeaveHoleFillingsOut) {
  const std::string path = ::testing::TempDir() + "/filled.ply";
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                         "property float z\nproperty uchar module\nend_header\n1 2 3 0\n4 5 6 255\n7 8 9 1\n";
  const PlyVertices all = ReadPlyVertices(path);
  EXPECT_EQ(all.module, (std::vector<int>{0, kPlyFilledModule, 1}));
  const MeasuredPoints measured = ReadMeasuredPlyPoints(path);
  EXPECT_EQ(measured.filled_skipped, 1);
  ASSERT_EQ(measured.points.size(), 2u);
  EXPECT_EQ(measured.points[1], Eigen::Vector3d(7, 8, 9));
  // Without a module property every vertex is measured.
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                         "property float z\nend_header\n1 2 3\n";
  EXPECT_EQ(ReadMeasuredPlyPoints(path).points.size(), 1u);
  EXPECT_EQ(ReadMeasuredPlyPoints(path).filled_skipped, 0);
}

TEST(PlyPoints, RejectsBrokenFiles) {
  const std::string dir = ::testing::TempDir();
  std::ofstream(dir + "/c.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                   "property float z\nend_header\n1 2 3\n";
  EXPECT_THROW(ReadPlyPoints(dir + "/c.ply"), InputError);  // truncated
  std::ofstream(dir + "/d.ply") << "not a ply\n";
  EXPECT_THROW(ReadPlyPoints(dir + "/d.ply"), InputError);
  std::ofstream(dir + "/e.ply") << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float a\nend_header\n1\n";
  EXPECT_THROW(ReadPlyPoints(dir + "/e.ply"), InputError);  // no xyz
  EXPECT_THROW(ReadPlyPoints(dir + "/missing.ply"), InputError);
}

}  // namespace
}  // namespace stereorig
