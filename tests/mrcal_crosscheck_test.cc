// Our Camera (mrcal's C API) against python3-mrcal, an independent
// implementation of the same lens models: projections must agree to 1e-9 px,
// and an exported .cameramodel must load in python3-mrcal and in mrcal's C
// reader and project identically. The reference numbers are computed here, at
// test time, by tests/reference/mrcal_project.py.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "calib/core/camera.h"
#include "calib/core/cameramodel_export.h"
#include "calib/core/mrcal_c.h"
#include "calib/core/rig_file.h"

namespace stereorig {
namespace {

const std::string kPython = "/usr/bin/python3";  // Debian's, which has python3-mrcal
const std::string kScript = std::string(STEREORIG_SOURCE_DIR) + "/tests/reference/mrcal_project.py";

std::string RunShell(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  EXPECT_NE(p, nullptr);
  char buf[4096];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  EXPECT_EQ(pclose(p), 0) << cmd;
  return out;
}

std::vector<Eigen::Vector2d> ReadQ(const std::string& path) {
  std::ifstream f(path);
  std::vector<Eigen::Vector2d> q;
  double x, y;
  while (f >> x >> y) q.emplace_back(x, y);
  return q;
}

// Points spread over the field of view and over 150..400 mm of depth.
std::vector<Eigen::Vector3d> RandomPoints(const Camera& cam, int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> ux(0, cam.imager_width_px() - 1), uy(0, cam.imager_height_px() - 1),
      uz(150, 400);
  std::vector<Eigen::Vector3d> p;
  while (static_cast<int>(p.size()) < n) {
    // Pinhole back-projection of a random pixel: in view for any mild lens.
    const double z = uz(*rng);
    p.emplace_back((ux(*rng) - cam.cx()) / cam.fx() * z, (uy(*rng) - cam.cy()) / cam.fy() * z, z);
  }
  return p;
}

Camera RandomOpencv8(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  return Camera("LENSMODEL_OPENCV8",
                {1024 + 5 * u(*rng), 1024 + 5 * u(*rng), 375.5 + 5 * u(*rng), 290.5 + 5 * u(*rng),
                 -0.1 + 0.02 * u(*rng), 0.09 + 0.02 * u(*rng), 1e-3 * u(*rng), 1e-3 * u(*rng), 0.02 * u(*rng),
                 0.01 * u(*rng), 0.01 * u(*rng), 0.01 * u(*rng)},
                752, 582);
}

Camera RandomSplined(std::mt19937* rng) {
  const std::string model = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=50";
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> intr = {1020 + 5 * u(*rng), 1021 + 5 * u(*rng), 375.5 + 3 * u(*rng), 290.5 + 3 * u(*rng)};
  // Non-trivial spline control values (the model's deviations from a pure
  // stereographic projection), so every knot matters.
  for (int i = 0; i < 2 * 16 * 12; ++i) intr.push_back(0.02 * u(*rng));
  return Camera(model, intr, 752, 582);
}

void ExpectProjectionMatchesPython(const Camera& cam, unsigned seed) {
  std::mt19937 rng(seed);
  const auto points = RandomPoints(cam, 500, &rng);
  // One file pair per process: ctest -j runs this binary's cases in parallel.
  const std::string dir = ::testing::TempDir() + "proj_" + std::to_string(getpid());
  const std::string in = dir + "_in.json", out = dir + "_out.txt";
  {
    std::ofstream f(in);
    f << "{\"lensmodel\": \"" << cam.lensmodel_name() << "\", \"intrinsics\": [";
    for (size_t i = 0; i < cam.intrinsics().size(); ++i) f << (i ? "," : "") << FormatDouble(cam.intrinsics()[i]);
    f << "], \"points\": [";
    for (size_t i = 0; i < points.size(); ++i)
      f << (i ? "," : "") << "[" << FormatDouble(points[i].x()) << "," << FormatDouble(points[i].y()) << ","
        << FormatDouble(points[i].z()) << "]";
    f << "]}";
  }
  RunShell(kPython + " " + kScript + " raw " + in + " " + out);
  const auto q_ref = ReadQ(out);
  ASSERT_EQ(q_ref.size(), points.size());
  double worst = 0;
  for (size_t i = 0; i < points.size(); ++i) worst = std::max(worst, (cam.Project(points[i]) - q_ref[i]).norm());
  EXPECT_LT(worst, 1e-9) << cam.lensmodel_name();
}

TEST(MrcalCrossCheck, Opencv8ProjectionAgreesWithPython) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    std::mt19937 rng(seed);
    ExpectProjectionMatchesPython(RandomOpencv8(&rng), seed);
  }
}

TEST(MrcalCrossCheck, SplinedProjectionAgreesWithPython) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    std::mt19937 rng(100 + seed);
    ExpectProjectionMatchesPython(RandomSplined(&rng), seed);
  }
}

TEST(MrcalCrossCheck, ExportedCameramodelLoadsInPythonAndCAndProjectsIdentically) {
  std::mt19937 rng(7);
  for (const Camera& cam : {RandomOpencv8(&rng), RandomSplined(&rng)}) {
    const Pose cam_from_ref = Pose::FromRotationVector({0.01, -0.1047, 0.02}, {-89.9, 0.3, 4.7});
    const std::string dir = ::testing::TempDir();
    const std::string model = dir + "/exported.cameramodel", pts = dir + "/pts.txt", out = dir + "/q.txt";
    WriteCameramodel(cam, cam_from_ref, model);
    const auto points = RandomPoints(cam, 200, &rng);
    {
      std::ofstream f(pts);
      for (const auto& p : points)
        f << FormatDouble(p.x()) << " " << FormatDouble(p.y()) << " " << FormatDouble(p.z()) << "\n";
    }
    const std::string printed = RunShell(kPython + " " + kScript + " model " + model + " " + pts + " " + out);
    const auto q_ref = ReadQ(out);
    ASSERT_EQ(q_ref.size(), points.size());
    for (size_t i = 0; i < points.size(); ++i) EXPECT_LT((cam.Project(points[i]) - q_ref[i]).norm(), 1e-9);
    // Extrinsics read back by python exactly.
    std::istringstream s(printed.substr(printed.find("extrinsics_rt_fromref") + 21));
    Eigen::Matrix<double, 6, 1> rt;
    for (int i = 0; i < 6; ++i) s >> rt[i];
    EXPECT_LT((rt.head<3>() - cam_from_ref.RotationVector()).norm(), 1e-15);
    EXPECT_LT((rt.tail<3>() - cam_from_ref.translation_mm()).norm(), 1e-12);
    EXPECT_NE(printed.find("imagersize 752 582"), std::string::npos);

    // mrcal's own C reader.
    mrcal_cameramodel_t* m = mrcal_read_cameramodel_file(model.c_str());
    ASSERT_NE(m, nullptr);
    const int n = mrcal_lensmodel_num_params(&m->lensmodel);
    ASSERT_EQ(n, static_cast<int>(cam.intrinsics().size()));
    for (int i = 0; i < n; ++i) EXPECT_EQ(m->intrinsics[i], cam.intrinsics()[i]);
    EXPECT_EQ(m->imagersize[0], 752u);
    mrcal_free_cameramodel(&m);
  }
}

}  // namespace
}  // namespace stereorig
