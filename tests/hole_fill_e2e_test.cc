// Hole filling end to end (issue 5: "the filled surface lies within 0.5 mm
// of the truth"): the simulator renders its cup (an open cylinder, 75 mm,
// with a floor and a rim bead); the runtime reconstructs it with
// shape_model: cylinder; every filled point is scored against the cup's
// analytic outer surface from the simulator's object.yaml. And its tuber
// (a bumpy ellipsoid, shape_model: ellipsoid): the fill must follow the
// bumps, scored against the simulator's dense truth surface.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calib/core/rig_file.h"
#include "reconstruct/hole_fill.h"
#include "reconstruct/metrology/ply_points.h"
#include "reconstruct/runtime.h"
#include "reconstruct/score.h"
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

TEST(HoleFillE2e, TheTubersFillFollowsItsBumps) {
  const std::string dir = testing::SimulateOneScene("tuber", 3, "hole_fill_e2e_tuber");
  const Rig rig = ReadRigFile(dir + "/truth/rig.yaml");
  const Runtime runtime(rig, RuntimeOptions{});
  const Reconstruction rec = runtime.Process(LoadCapture(dir + "/scenes/tuber/active", rig), false);
  const std::vector<Eigen::Vector3d> truth = ReadPlyPoints(dir + "/truth/scenes/tuber/surface.ply");
  // The same measured cloud filled from the ellipsoid alone and following
  // the residuals; the filled points scored against the dense truth.
  auto filled_score = [&](bool follow) {
    RuntimeOptions o;
    o.shape_model = ShapeModel::kEllipsoid;
    o.fill_follow_residuals = follow;
    PointCloud cloud = rec.cloud;
    Mesh mesh;
    const HoleFillResult fill = FillHolesFromModel(rec.cloud, o, &cloud, &mesh);
    EXPECT_TRUE(fill.ok) << fill.message;
    std::printf("%s; %d points filled\n", fill.message.c_str(), fill.added_points);
    const ErrorFigures f = ScoreAgainstTruth(cloud, truth, rig.num_modules()).filled;
    std::printf("  filled against the truth: mean %.3f p95 %.3f max %.3f mm, %.1f%% within 0.5 mm\n", f.mean_abs_mm,
                f.p95_abs_mm, f.max_abs_mm, 100 * f.within_0_5_mm);
    return f;
  };
  const ErrorFigures model_only = filled_score(false), following = filled_score(true);
  ASSERT_GT(following.points, 5000);
  // The tuber's bumps (relative 0.05, ~2 mm) put the ellipsoid's fill off
  // by up to 1-2 mm (seed 3: 0.30 mean, 1.0 max; the demo's seed 1: 0.70
  // mean, 1.8 max, 42% within 0.5 mm).
  EXPECT_GT(model_only.max_abs_mm, 0.8);
  // Following the residuals (session 18: seed 3 0.09 mean, 0.60 max, 98.3%
  // within 0.5 mm; the demo's seed 1 0.12 mean, 0.41 max, 100%; seeds 5-7
  // 0.04-0.12 mean, 97.8-100%: the bumps in what no module saw are not in
  // the data). The measured points' noise (0.07 mm) is averaged away by the
  // field; the margins here are for other seeds' bumps and holes.
  EXPECT_GT(following.within_0_5_mm, 0.95);
  EXPECT_LT(following.mean_abs_mm, 0.4 * model_only.mean_abs_mm);
  EXPECT_LT(following.max_abs_mm, model_only.max_abs_mm);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stereorig
