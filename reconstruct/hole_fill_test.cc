// Hole filling against the analytic truth: noisy partial clouds of a
// sphere, a cylinder and an ellipsoid go in; the filled points must lie on
// the true surface and cover what was not seen. Failed fits add nothing.
#include "reconstruct/hole_fill.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <functional>
#include <random>
#include <string>

#include "reconstruct/metrology/ply_points.h"
#include "reconstruct/metrology/synthetic_shapes.h"
#include "reconstruct/ply_io.h"

namespace stereorig {
namespace {

// `points` random points of the half of a sphere (centre c, radius r) facing a
// camera at z = 0, 0.05 mm radial noise (like a good module); module 0 on
// the side x < 0, 1 on the other.
PointCloud SeenHalfOfSphere(const Eigen::Vector3d& c, double r, size_t points, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 0.05);
  std::uniform_real_distribution<double> u(-1, 1);
  PointCloud cloud;
  while (cloud.size() < points) {
    Eigen::Vector3d v(u(rng), u(rng), u(rng));
    if (v.norm() > 1 || v.norm() < 0.1) continue;
    v.normalize();
    if (v.z() > 0) continue;
    cloud.xyz_mm.push_back((c + (r + noise(rng)) * v).cast<float>());
    cloud.normal.push_back(v.cast<float>());
    cloud.intensity.push_back(100);
    cloud.module.push_back(v.x() < 0 ? 0 : 1);
    cloud.confidence.push_back(1);
  }
  return cloud;
}

TEST(HoleFill, SphereClosesTheUnseenHalfOnTheTrueSurface) {
  const Eigen::Vector3d c(10, -5, 200);
  const double r = 19.05;
  const PointCloud cloud = SeenHalfOfSphere(c, r, 20000, 5);
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

// The mesh PLY keeps each vertex's module, hole filling's as 255, so
// `stereorig verify` skips the same filled points in the mesh as in the
// cloud: the mesh held x, y, z only, and verify took every vertex of it as
// measured (the shape model's points entered the fit).
TEST(HoleFill, TheMeshPlyKeepsEachVertexsModuleAndHoleFillingsAre255) {
  const PointCloud cloud = SeenHalfOfSphere(Eigen::Vector3d(10, -5, 200), 19.05, 2000, 7);
  RuntimeOptions o;
  o.shape_model = ShapeModel::kSphere;
  PointCloud out = cloud;
  Mesh mesh;
  mesh.triangles.emplace_back(0, 1, 2);  // as the runtime's organised mesh: over the measured points
  const HoleFillResult fill = FillHolesFromModel(cloud, o, &out, &mesh);
  ASSERT_TRUE(fill.ok) << fill.message;
  ASSERT_GT(fill.added_points, 1000);

  const std::string path = ::testing::TempDir() + "/hole_fill_mesh_" + std::to_string(getpid()) + ".ply";
  WriteMesh(out, mesh, path);
  const PlyVertices read = ReadPlyVertices(path);  // the metrology reader, as verify reads it
  std::remove(path.c_str());
  ASSERT_EQ(read.points.size(), out.size());
  ASSERT_EQ(read.module.size(), out.size());
  EXPECT_EQ(read.faces, static_cast<long long>(mesh.triangles.size()));
  int filled = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(read.module[i], int(out.module[i])) << i;  // the cloud's module, vertex for point
    EXPECT_EQ(read.module[i] == kPlyFilledModule, i >= cloud.size()) << i;
    filled += read.module[i] == kPlyFilledModule;
  }
  EXPECT_EQ(filled, fill.added_points);
  // The same records as the cloud PLY's vertices: every field, not only the module.
  const std::string cloud_bytes = EncodeCloudPly(out), mesh_bytes = EncodeMesh(out, mesh, path);
  const std::string cloud_body = cloud_bytes.substr(cloud_bytes.find("end_header\n") + 11);
  const std::string mesh_body = mesh_bytes.substr(mesh_bytes.find("end_header\n") + 11);
  EXPECT_EQ(mesh_body.substr(0, cloud_body.size()), cloud_body);
}

PointCloud ToCloud(const testing::NoisyCloud& noisy) {
  PointCloud cloud;
  for (size_t i = 0; i < noisy.points.size(); ++i) {
    cloud.xyz_mm.push_back(noisy.points[i].cast<float>());
    cloud.normal.push_back(noisy.normals[i].cast<float>());
    cloud.intensity.push_back(100);
    cloud.module.push_back(0);
    cloud.confidence.push_back(1);
  }
  return cloud;
}

// The fill of `model` on `measured`: the filled points only, and the mesh
// over `cloud` (measured, then filled).
struct Fill {
  HoleFillResult result;
  std::vector<Eigen::Vector3d> points;
  PointCloud cloud;
  Mesh mesh;
};
Fill FillWith(ShapeModel model, const PointCloud& measured, double object_size_mm = 100) {
  RuntimeOptions o;
  o.shape_model = model;
  o.object_size_mm = object_size_mm;
  o.Check();
  Fill f;
  f.cloud = measured;
  f.result = FillHolesFromModel(measured, o, &f.cloud, &f.mesh);
  for (size_t i = measured.size(); i < f.cloud.size(); ++i) {
    EXPECT_EQ(f.cloud.module[i], kFilledModule);
    f.points.push_back(f.cloud.xyz_mm[i].cast<double>());
  }
  EXPECT_EQ(f.result.added_points, static_cast<int>(f.points.size()));
  // The fill's triangles join the filled points only, by their index in the cloud.
  for (const Eigen::Vector3i& t : f.mesh.triangles) {
    EXPECT_GE(t.minCoeff(), static_cast<int>(measured.size()));
    EXPECT_LT(t.maxCoeff(), static_cast<int>(f.cloud.size()));
  }
  return f;
}

// Every triangle faces away from `inside` (a point on the axis or the centre
// nearest to the triangle): the lattice's orientation is right.
int InwardTriangles(const Fill& fill, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& inside) {
  int inward = 0;
  const std::vector<Eigen::Vector3f>& v_mm = fill.cloud.xyz_mm;
  for (const auto& t : fill.mesh.triangles) {
    const Eigen::Vector3d a = v_mm[t[0]].cast<double>(), b = v_mm[t[1]].cast<double>(), c = v_mm[t[2]].cast<double>();
    const Eigen::Vector3d centroid = (a + b + c) / 3;
    inward += (b - a).cross(c - a).dot(centroid - inside(centroid)) < 0;
  }
  return inward;
}

// Issue 5: "the filled surface lies within 0.5 mm of the truth". The cloud:
// a cup-sized cylinder (r 37.5 mm, 70 mm long, axis tilted 4 degrees from
// the vertical) as two facing modules see it, 0.05 mm noise along the
// normal, normals 3 degrees off, 5% gross outliers.
TEST(HoleFill, CylinderClosesTheUnseenSidesOnTheTrueSurface) {
  const Eigen::Vector3d c(5, -3, 200), axis = Eigen::Vector3d(0.05, 1, 0.04).normalized();
  const double r = 37.5, len = 70;
  const PointCloud cloud =
      ToCloud(testing::SeenByTwoFacingCameras(testing::CylinderSurface(c, axis, r, len), c, testing::NoiseSpec{}));
  const Fill fill = FillWith(ShapeModel::kCylinder, cloud);
  ASSERT_TRUE(fill.result.ok) << fill.result.message;
  std::printf("%s: %d points added\n", fill.result.message.c_str(), fill.result.added_points);
  double worst = 0;
  int on_the_sides = 0;
  for (const auto& p : fill.points) {
    const Eigen::Vector3d v = p - c;
    worst = std::max(worst, std::abs((v - v.dot(axis) * axis).norm() - r));
    EXPECT_LT(std::abs(v.dot(axis)), 0.5 * len + 1.0);  // within the measured extent
    on_the_sides += std::abs(v.x()) > 0.8 * r;          // the flanks no camera on the z axis faces
  }
  // The fit of ~19k points with 0.05 mm noise puts the radius and the axis
  // to ~0.005 mm (shape_fit_test): 0.05 mm is 10x that, and the issue asks
  // for 0.5 mm.
  EXPECT_LT(worst, 0.05);
  // The unseen flanks: at 70 degrees from grazing, each camera sees a
  // +-70 degree strip, leaving 2 x 40 degrees: ~2 x 0.11 x 2 pi r x len at
  // 1 mm spacing = 3700 samples, less the 2 mm band along the seen edges.
  EXPECT_GT(fill.result.added_points, 2500);
  EXPECT_GT(on_the_sides, 0.9 * fill.result.added_points);
  EXPECT_GT(fill.mesh.triangles.size(), size_t(fill.result.added_points));
  EXPECT_EQ(
      InwardTriangles(fill, [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(c + (p - c).dot(axis) * axis); }),
      0);
}

// The same for a tuber-sized ellipsoid (semi-axes 42, 30, 27 mm, turned).
TEST(HoleFill, EllipsoidClosesTheUnseenRimOnTheTrueSurface) {
  const Eigen::Vector3d c(-4, 6, 205), axes(42, 30, 27);
  const Eigen::Matrix3d rot =
      (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 0, 1).normalized()))
          .toRotationMatrix();
  const PointCloud cloud =
      ToCloud(testing::SeenByTwoFacingCameras(testing::EllipsoidSurface(c, rot, axes), c, testing::NoiseSpec{}));
  const Fill fill = FillWith(ShapeModel::kEllipsoid, cloud);
  ASSERT_TRUE(fill.result.ok) << fill.result.message;
  std::printf("%s: %d points added\n", fill.result.message.c_str(), fill.result.added_points);
  double worst = 0;
  for (const auto& p : fill.points) worst = std::max(worst, testing::EllipsoidDistanceBound(c, rot, axes, p));
  // Distance bound along the ray from the centre (>= the true distance).
  // The caps pin the fit to ~0.01-0.02 mm (shape_fit_test); the unseen rim
  // is an extrapolation, so 0.1 mm = 5x that; the issue asks for 0.5 mm.
  EXPECT_LT(worst, 0.1);
  EXPECT_GT(fill.result.added_points, 1000);
  EXPECT_EQ(InwardTriangles(fill, [&](const Eigen::Vector3d&) { return c; }), 0);
}

// Issue 5 on a real-ish object: a tuber-sized ellipsoid with low-frequency
// radial bumps (|u| = 1 + h(u/|u|), u = p / semi-axes, |h| <= 0.05: up to
// ~2 mm), like the simulator's tuber. The ellipsoid alone misses the bumps
// by up to ~2 mm; following the measured residuals, the fill must follow
// them where it continues the seen surface.
TEST(HoleFill, BumpyEllipsoidFillFollowsTheBumps) {
  const Eigen::Vector3d c(-4, 6, 205), axes(42, 30, 27);
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  const Eigen::Vector3d g[3] = {Eigen::Vector3d(1, 0.3, 0).normalized(), Eigen::Vector3d(-0.2, 1, 0.5).normalized(),
                                Eigen::Vector3d(0.4, -0.3, 1).normalized()};
  const double f[3] = {2.3, 3.1, 2.7}, phase[3] = {0.3, 1.9, 4.0};
  auto h = [&](const Eigen::Vector3d& w) {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += std::sin(f[k] * g[k].dot(w) + phase[k]);
    return 0.05 * sum / 3;
  };
  const auto ellipsoid = testing::EllipsoidSurface(c, rot, axes);
  auto bumpy = [&](double a, double b, Eigen::Vector3d* n) {
    const Eigen::Vector3d p = ellipsoid(a, b, n);  // n: the ellipsoid's normal (visibility, noise direction)
    const Eigen::Vector3d w = axes.cwiseInverse().cwiseProduct(rot.transpose() * (p - c));
    return Eigen::Vector3d(c + (1 + h(w)) * (p - c));
  };
  // Distance bound along the ray from the centre (>= the true distance).
  auto truth_distance = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d u = axes.cwiseInverse().cwiseProduct(rot.transpose() * (p - c));
    return (p - c).norm() * std::abs(1 - (1 + h(u.normalized())) / u.norm());
  };
  const PointCloud cloud = ToCloud(testing::SeenByTwoFacingCameras(bumpy, c, testing::NoiseSpec{}));
  struct Figures {
    double mean = 0, worst = 0, within_0_5 = 0;
    int points = 0;
  };
  auto fill_figures = [&](bool follow) {
    RuntimeOptions o;
    o.shape_model = ShapeModel::kEllipsoid;
    o.fill_follow_residuals = follow;
    PointCloud out = cloud;
    Mesh mesh;
    const HoleFillResult r = FillHolesFromModel(cloud, o, &out, &mesh);
    EXPECT_TRUE(r.ok) << r.message;
    std::printf("%s: %d points added\n", r.message.c_str(), r.added_points);
    Figures fig;
    for (size_t i = cloud.size(); i < out.size(); ++i) {
      const double d = truth_distance(out.xyz_mm[i].cast<double>());
      fig.mean += d;
      fig.worst = std::max(fig.worst, d);
      fig.within_0_5 += d <= 0.5;
      ++fig.points;
    }
    fig.mean /= std::max(1, fig.points);
    fig.within_0_5 /= std::max(1, fig.points);
    std::printf("  filled points against the bumpy truth: mean %.3f mm, worst %.3f mm, %.1f%% within 0.5 mm\n",
                fig.mean, fig.worst, 100 * fig.within_0_5);
    return fig;
  };
  const Figures model_only = fill_figures(false), following = fill_figures(true);
  ASSERT_GT(following.points, 1000);
  // The ellipsoid alone is off by the bumps (this is what the test is about).
  EXPECT_GT(model_only.worst, 1.0);
  // Following the residuals: the unseen rim is at most ~15 mm from the seen
  // caps, about a length scale, so the field carries the bumps there. The
  // 0.05 mm point noise is averaged away (cell means of ~20 points); what
  // is left is the field's extrapolation, which decays to the model deep in
  // a hole: the 0.5 mm holds for nearly every point (measured:
  // 0.028 mm mean, 0.21 mm worst, against 0.32 / 1.1 mm for the model).
  EXPECT_GT(following.within_0_5, 0.99);
  EXPECT_LT(following.mean, 0.25 * model_only.mean);
  EXPECT_LT(following.worst, 0.6 * model_only.worst);
}

// A fit that fails is reported and nothing is added: too few points, an
// object larger than object_size_mm, a model of the wrong kind.
TEST(HoleFill, AFailedFitIsReportedAndNotUsed) {
  const Eigen::Vector3d c(5, -3, 200);
  const PointCloud cup = ToCloud(testing::SeenByTwoFacingCameras(
      testing::CylinderSurface(c, Eigen::Vector3d::UnitY(), 37.5, 70), c, testing::NoiseSpec{}));
  PointCloud few;
  for (size_t i = 0; i < 50; ++i) few.Append(PointCloud{{cup.xyz_mm[i]}, {cup.normal[i]}, {1}, {0}, {1}});
  for (ShapeModel m : {ShapeModel::kSphere, ShapeModel::kCylinder, ShapeModel::kEllipsoid}) {
    const Fill f = FillWith(m, few);
    EXPECT_FALSE(f.result.ok) << ShapeModelName(m);
    EXPECT_NE(f.result.message.find("too few points"), std::string::npos) << f.result.message;
    EXPECT_TRUE(f.points.empty());
  }
  // A 75 mm cup when the options say objects are at most 50 mm.
  Fill f = FillWith(ShapeModel::kCylinder, cup, 50);
  EXPECT_FALSE(f.result.ok);
  EXPECT_NE(f.result.message.find("exceeds object_size_mm"), std::string::npos) << f.result.message;
  EXPECT_TRUE(f.points.empty() && f.mesh.triangles.empty());
  // A cylinder sought in a sphere's cloud explains too little of it.
  const PointCloud ball = ToCloud(testing::SeenByTwoFacingCameras(
      testing::EllipsoidSurface(c, Eigen::Matrix3d::Identity(), Eigen::Vector3d(25, 25, 25)), c, testing::NoiseSpec{}));
  f = FillWith(ShapeModel::kCylinder, ball);
  EXPECT_FALSE(f.result.ok) << f.result.message;
  EXPECT_TRUE(f.points.empty());
}

}  // namespace
}  // namespace stereorig
