// Hole filling against the analytic truth: a noisy half sphere goes in; the
// filled points must lie on the true sphere and cover the unseen half.
#include "reconstruct/hole_fill.h"

#include <gtest/gtest.h>

#include <random>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

TEST(HoleFill, SphereClosesTheUnseenHalfOnTheTrueSurface) {
  const Eigen::Vector3d c(10, -5, 200);
  const double r = 19.05;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.05);  // 0.05 mm radial noise, like a good module
  std::uniform_real_distribution<double> u(-1, 1);
  PointCloud cloud;
  while (cloud.size() < 20000) {
    Eigen::Vector3d v(u(rng), u(rng), u(rng));
    if (v.norm() > 1 || v.norm() < 0.1) continue;
    v.normalize();
    if (v.z() > 0) continue;  // only the half facing a camera at z = 0
    cloud.xyz_mm.push_back((c + (r + noise(rng)) * v).cast<float>());
    cloud.normal.push_back(v.cast<float>());
    cloud.intensity.push_back(100);
    cloud.module.push_back(0);
    cloud.confidence.push_back(1);
  }
  RuntimeOptions o;
  o.shape_model = ShapeModel::kSphere;
  PointCloud out = cloud;
  Mesh mesh;
  const HoleFillResult fill = FillHolesFromModel(cloud, o, &out, &mesh);
  ASSERT_TRUE(fill.ok) << fill.message;
  // The unseen half: 2 pi r^2 at 1 mm spacing is ~2300 samples (the lattice
  // is denser near the poles), minus the 2 mm band next to the seen half.
  EXPECT_GT(fill.added_points, 1500);
  double worst = 0;
  int behind = 0;
  for (size_t i = cloud.size(); i < out.size(); ++i) {
    EXPECT_EQ(out.module[i], kFilledModule);
    const Eigen::Vector3d p = out.xyz_mm[i].cast<double>();
    worst = std::max(worst, std::abs((p - c).norm() - r));
    behind += p.z() > c.z();
  }
  // The fit of 20k points with 0.05 mm noise: centre and radius to ~1e-3 mm,
  // far inside the 0.5 mm for the filled surface.
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(behind, 0.9 * fill.added_points);  // it fills the unseen side
  EXPECT_GT(mesh.triangles.size(), size_t(fill.added_points));
}

TEST(HoleFill, UnbuiltModelsAreRejectedByTheOptions) {
  RuntimeOptions o;
  o.shape_model = ShapeModel::kCylinder;
  EXPECT_THROW(o.Check(), InputError);
}

}  // namespace
}  // namespace stereorig
