// Hole filling end to end (issue 5: "the filled surface lies within 0.5 mm
// of the truth"): the simulator renders its cup (an open cylinder, 75 mm,
// with a floor and a rim bead); the runtime reconstructs it with
// shape_model: cylinder; every filled point is scored against the cup's
// analytic outer surface from the simulator's object.yaml.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/core/rig_file.h"
#include "reconstruct/runtime.h"
#include "tests/sim_scene.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

TEST(HoleFillE2e, TheCupsCylinderFillLiesOnItsTrueSurface) {
  const std::string dir = testing::SimulateOneScene("cup", 3, "hole_fill_e2e");
  const Rig rig = ReadRigFile(dir + "/truth/rig.yaml");
  RuntimeOptions o;
  o.shape_model = ShapeModel::kCylinder;
  const Runtime runtime(rig, o);
  const Reconstruction rec = runtime.Process(LoadCapture(dir + "/scenes/cup/active", rig), true);
  std::printf("%s; %d points filled\n", rec.shape_fit.c_str(), rec.filled_points);
  ASSERT_GT(rec.filled_points, 1000) << rec.shape_fit;

  // The truth: module0_from_object (the truth rig's reference is module 0),
  // object z up the axis from the outside bottom.
  const YAML::Node obj = YAML::LoadFile(dir + "/truth/scenes/cup/object.yaml")["objects"][0];
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = obj["module0_from_object"][r][c].as<double>();
  const YAML::Node p = obj["parameters"];
  const double radius = 0.5 * p["outer_diameter_mm"].as<double>(), height = p["height_mm"].as<double>();
  const double bead = p["rim_bead_radius_mm"].as<double>(), bead_major = p["rim_bead_major_radius_mm"].as<double>();
  // Where the bead meets the outer wall: the wall is surface below it only.
  const double wall_top = height - std::sqrt(bead * bead - std::pow(radius - bead_major, 2));
  const Eigen::Matrix3d rot = m.block<3, 3>(0, 0);
  const Eigen::Vector3d origin = m.block<3, 1>(0, 3);
  auto truth_distance = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d q = rot.transpose() * (x - origin);
    const double rho = std::hypot(q.x(), q.y()), z = q.z();
    const double wall = std::hypot(rho - radius, std::max(0.0, z - wall_top) + std::max(0.0, -z));
    const double rim = std::abs(std::hypot(rho - bead_major, z - height) - bead);
    const double floor = rho <= radius ? std::abs(z) : std::hypot(rho - radius, z);
    return std::min({wall, rim, floor});
  };
  double worst = 0, sum = 0;
  int n = 0;
  for (size_t i = 0; i < rec.cloud.size(); ++i) {
    if (rec.cloud.module[i] != kFilledModule) continue;
    const double d = truth_distance(rec.cloud.xyz_mm[i].cast<double>());
    worst = std::max(worst, d);
    sum += d;
    ++n;
  }
  std::printf("filled points against the truth: mean %.4f mm, worst %.4f mm over %d points\n", sum / n, worst, n);
  // Issue 5's bound. The measured cloud's noise (~0.07 mm rms on the wall)
  // puts the fitted radius and axis within ~0.01 mm; the worst filled points
  // are those at the top of the fitted extent, under the rim bead's bulge.
  EXPECT_LT(worst, 0.5);
  EXPECT_LT(sum / n, 0.1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stereorig
