#include "calib/mrcal_problem.h"

#include <algorithm>
#include <optional>
#include <string_view>

#include "calib/core/input_error.h"
#include "calib/scoped_stderr_capture.h"

namespace stereorig {
namespace {

// mrcal_optimize prints each pass of its outlier loop to stderr whatever its
// verbose flag: "mrcal.c(5351): Threw out some outliers (have a total of 1737
// now); going again". Its total counts every pool entry of weight < 0, the
// corners a view did not see among them, so beside our summary's "6 outliers"
// (the outliers alone, which the report gives) it only misleads.
bool IsOutlierLoopLine(std::string_view line) {
  return line.rfind("mrcal.c(", 0) == 0 && line.find("Threw out some outliers") != std::string_view::npos;
}

}  // namespace

bool MrcalProblem::SetLensmodel(const std::string& name) {
  if (!mrcal_lensmodel_from_name(&lensmodel, name.c_str())) return false;
  if (!mrcal_lensmodel_type_is_valid(lensmodel.type)) return false;
  lensmodel_name = name;
  return true;
}

int MrcalProblem::num_states() const {
  return mrcal_num_states(num_intrinsics_cameras, num_extrinsics(), num_frames(), 0, 0, num_observations(), selections,
                          &lensmodel);
}

int MrcalProblem::num_measurements() const {
  return mrcal_num_measurements(num_observations(), 0, corners_x, corners_y, num_intrinsics_cameras, num_extrinsics(),
                                num_frames(), 0, 0, selections, &lensmodel);
}

int MrcalProblem::num_measurements_boards() const {
  return mrcal_num_measurements_boards(num_observations(), corners_x, corners_y);
}

mrcal_stats_t MrcalProblem::Optimize(bool verbose) {
  STEREORIG_CHECK(static_cast<int>(intrinsics.size()) == num_intrinsics_cameras * num_params());
  STEREORIG_CHECK(static_cast<int>(pool.size()) == num_observations() * corners_x * corners_y);
  const mrcal_problem_constants_t constants = {.point_min_range = -1.0, .point_max_range = -1.0};
  // Verbose asks for mrcal's own account, whole; anything else it prints
  // (an error) comes through unchanged.
  std::optional<ScopedStderrCapture> quiet;
  if (!verbose) quiet.emplace(IsOutlierLoopLine);
  return mrcal_optimize(nullptr, 0, nullptr, 0, intrinsics.data(), extrinsics_fromref.data(), frames_toref.data(),
                        nullptr, nullptr, num_intrinsics_cameras, num_extrinsics(), num_frames(), 0, 0,
                        observations.data(), nullptr, num_observations(), 0, pool.data(), &lensmodel,
                        imagersizes.data(), selections, &constants, spacing_mm, corners_x, corners_y, verbose, false);
}

std::vector<double> MrcalProblem::Residuals() const {
  const mrcal_problem_constants_t constants = {.point_min_range = -1.0, .point_max_range = -1.0};
  std::vector<double> b(num_states()), x(num_measurements());
  const bool ok = mrcal_optimizer_callback(
      b.data(), static_cast<int>(b.size() * sizeof(double)), x.data(), static_cast<int>(x.size() * sizeof(double)),
      nullptr, intrinsics.data(), extrinsics_fromref.data(), frames_toref.data(), nullptr, nullptr,
      num_intrinsics_cameras, num_extrinsics(), num_frames(), 0, 0, observations.data(), nullptr, num_observations(), 0,
      pool.data(), &lensmodel, imagersizes.data(), selections, &constants, spacing_mm, corners_x, corners_y, false);
  STEREORIG_CHECK(ok);
  return x;
}

int MrcalProblem::CountNonPositiveWeights() const {
  int n = 0;
  for (const auto& p : pool) n += p.z <= 0.0;
  return n;
}

void MrcalProblem::SelectPosesOnly() {
  selections = {.do_optimize_intrinsics_core = false,
                .do_optimize_intrinsics_distortions = false,
                .do_optimize_extrinsics = true,
                .do_optimize_frames = true,
                .do_optimize_calobject_warp = false,
                .do_apply_regularization = false,
                .do_apply_outlier_rejection = false};
}

mrcal_pose_t MrcalProblem::ToMrcal(const Pose& a_from_b) {
  const Eigen::Vector3d r = a_from_b.RotationVector();
  const Eigen::Vector3d& t = a_from_b.translation_mm();
  mrcal_pose_t out;
  out.r = {.xyz = {r.x(), r.y(), r.z()}};
  out.t = {.xyz = {t.x(), t.y(), t.z()}};
  return out;
}

Pose MrcalProblem::FromMrcal(const mrcal_pose_t& rt) {
  return Pose::FromRotationVector(Eigen::Vector3d(rt.r.x, rt.r.y, rt.r.z), Eigen::Vector3d(rt.t.x, rt.t.y, rt.t.z));
}

double MrcalProblem::MedianBoardDistanceMm(int icam_intrinsics) const {
  const Eigen::Vector3d centre_in_frame(0.5 * (corners_x - 1) * spacing_mm, 0.5 * (corners_y - 1) * spacing_mm, 0);
  std::vector<double> distances_mm;
  for (const mrcal_observation_board_t& o : observations) {
    if (o.icam.intrinsics != icam_intrinsics) continue;
    Eigen::Vector3d p = FromMrcal(frames_toref[o.iframe]) * centre_in_frame;  // reference frame
    if (o.icam.extrinsics >= 0) p = FromMrcal(extrinsics_fromref[o.icam.extrinsics]) * p;
    distances_mm.push_back(p.norm());
  }
  if (distances_mm.empty()) return 0;
  const auto middle = distances_mm.begin() + distances_mm.size() / 2;
  std::nth_element(distances_mm.begin(), middle, distances_mm.end());
  return *middle;
}

}  // namespace stereorig
