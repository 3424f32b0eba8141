// Our port of mrcal's projection_uncertainty against python3-mrcal's own, on
// the same solved problems (a one-camera stage-1 problem, a two-camera stage-2
// problem whose right camera carries extrinsics, and a splined model). The two
// are the same formula evaluated by different code (our C++ with CHOLMOD, and
// mrcal's Python with its own CHOLMOD wrapper), so they must agree to rounding:
// 1e-8 relative on Var(q) (measured: ~1e-12 for OPENCV8, ~1e-10 for the
// ill-conditioned splined problem).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "calib/calib_test_util.h"
#include "calib/intrinsics.h"
#include "calib/json_writer.h"
#include "calib/projection_uncertainty.h"
#include "calib/stereo.h"

namespace stereorig {
namespace {

std::string DumpProblem(const MrcalProblem& p, const std::vector<std::pair<int, Eigen::Vector3d>>& queries) {
  JsonWriter j;
  j.BeginObject().String("lensmodel", p.lensmodel_name).Int("ncams", p.num_intrinsics_cameras);
  j.Int("corners_x", p.corners_x).Int("corners_y", p.corners_y).Number("spacing", p.spacing_mm);
  j.Bool("core", p.selections.do_optimize_intrinsics_core);
  j.Bool("distortions", p.selections.do_optimize_intrinsics_distortions);
  j.Bool("regularization", p.selections.do_apply_regularization);
  j.Numbers("intrinsics", p.intrinsics);
  std::vector<double> v;
  for (const auto& e : p.extrinsics_fromref) v.insert(v.end(), &e.r.x, &e.r.x + 6);
  j.Numbers("extrinsics", v);
  v.clear();
  for (const auto& f : p.frames_toref) v.insert(v.end(), &f.r.x, &f.r.x + 6);
  j.Numbers("frames", v);
  v.clear();
  for (const auto& o : p.observations)
    v.insert(v.end(), {double(o.iframe), double(o.icam.intrinsics), double(o.icam.extrinsics)});
  j.Numbers("indices", v);
  v.clear();
  for (const auto& q : p.pool) v.insert(v.end(), {q.x, q.y, q.z});
  j.Numbers("pool", v);
  v.assign(p.imagersizes.begin(), p.imagersizes.end());
  j.Numbers("imagersizes", v);
  j.BeginArray("queries");
  for (const auto& [icam, pc] : queries) {
    j.BeginObject().Int("icam", icam).Numbers("p_cam", {pc.x(), pc.y(), pc.z()}).EndObject();
  }
  j.EndArray().EndObject();
  return j.str();
}

void ExpectMatchesPython(const MrcalProblem& p, const std::vector<std::pair<int, Eigen::Vector3d>>& queries,
                         const std::string& tag) {
  const std::string dir = ::testing::TempDir();
  const std::string in = dir + "/unc_" + tag + ".json", out = dir + "/unc_" + tag + ".txt";
  std::ofstream(in) << DumpProblem(p, queries);
  const std::string cmd = "/usr/bin/python3 " + std::string(STEREORIG_SOURCE_DIR) +
                          "/calib/testdata/mrcal_uncertainty.py " + in + " " + out;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream f(out);
  ProjectionUncertaintyEvaluator eval(p);
  ASSERT_TRUE(eval.ok()) << eval.message();
  for (const auto& [icam, pc] : queries) {
    double v[4], sigma;
    ASSERT_TRUE(f >> v[0] >> v[1] >> v[2] >> v[3] >> sigma);
    EXPECT_NEAR(eval.observed_pixel_sigma_px(), sigma, 1e-9 * sigma) << tag;
    const ProjectionUncertainty u = eval.AtPoint(icam, pc);
    const double scale = std::max(std::abs(v[0]), std::abs(v[3]));
    EXPECT_GT(scale, 0.0);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(u.covariance_px2(i / 2, i % 2), v[i], 1e-8 * scale)
          << tag << " icam " << icam << " p " << pc.transpose() << " element " << i;
    }
  }
}

TEST(ProjectionUncertainty, Stage1MatchesPythonMrcal) {
  const auto scene = testing::MakeDefaultScene(3, 14, 0.2);
  IntrinsicsOptions opt;
  const auto r = CalibrateIntrinsics(0, scene.data.input.cameras[0], scene.data.input.target,
                                     testing::ViewsOf(scene.data.input, 0), opt, "test");
  std::vector<std::pair<int, Eigen::Vector3d>> q = {
      {0, {0, 0, 200}}, {0, {-60, -45, 210}}, {0, {70, 50, 190}}, {0, {10, -30, 400}}};
  ExpectMatchesPython(r.problem, q, "stage1");
}

TEST(ProjectionUncertainty, Stage2WithExtrinsicsMatchesPythonMrcal) {
  const auto scene = testing::MakeDefaultScene(4, 12, 0.2);
  const CalibrationInput& in = scene.data.input;
  IntrinsicsOptions opt;
  const auto l = CalibrateIntrinsics(0, in.cameras[0], in.target, testing::ViewsOf(in, 0), opt, "test");
  const auto r = CalibrateIntrinsics(1, in.cameras[1], in.target, testing::ViewsOf(in, 1), opt, "test");
  const auto s = CalibrateStereo(0, in.modules[0], l, r, testing::ViewsOf(in, 0), testing::ViewsOf(in, 1), in,
                                 StereoOptions(), opt);
  std::vector<std::pair<int, Eigen::Vector3d>> q = {{0, {0, 0, 200}}, {1, {0, 0, 200}}, {1, {-50, 40, 220}}};
  ExpectMatchesPython(s.problem, q, "stage2");
}

TEST(ProjectionUncertainty, SplinedModelMatchesPythonMrcal) {
  const auto scene = testing::MakeDefaultScene(5, 14, 0.2);
  IntrinsicsOptions opt;
  opt.lensmodel = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=45";
  const auto r = CalibrateIntrinsics(0, scene.data.input.cameras[0], scene.data.input.target,
                                     testing::ViewsOf(scene.data.input, 0), opt, "test");
  std::vector<std::pair<int, Eigen::Vector3d>> q = {{0, {0, 0, 200}}, {0, {-40, 30, 200}}};
  ExpectMatchesPython(r.problem, q, "splined");
}

}  // namespace
}  // namespace stereorig
