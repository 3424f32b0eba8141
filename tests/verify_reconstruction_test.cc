// VDI/VDE 2634-2 figures on RECONSTRUCTIONS of the simulated artifacts
// (issue 6, "Judged by"): the simulator renders the sphere, the ball bar and
// the plate; the runtime reconstructs each; our verify (vdi2634.h) computes
// P_F, P_S, SD and F; and a second, independent fit written here computes
// them again from the same points with other algorithms:
//   - sphere: an algebraic (Kasa) linear fit solved by OpenCV's SVD, refined
//     on the geometric distance by Ceres' Levenberg-Marquardt, started from
//     the simulator's truth pose (ours: 4-point RANSAC + hand Gauss-Newton);
//   - plane: the smallest right singular vector of the centred points by
//     Eigen's JacobiSVD, the face picked with the simulator's truth pose, its
//     outline from OpenCV's convex hull (ours: 3-point RANSAC +
//     eigen-decomposition of the scatter, our own hull).
// Both apply the same point selection, the one the standard allows and
// vdi2634.h documents: the points within the capture band of the shape
// (5 mm, at least twice the MPE), the ball bar's shaft cone left out, the
// plate's edge margin (inside the smallest rectangle holding the face) left
// out, and at most 0.3% of the points with the largest residuals excluded.
//
// Every figure must agree within 0.005 mm. Then each is compared with the
// accuracy issue 5 asks of the runtime (merged modules: mean |e| <= 0.15 mm).
//
// The rig is the simulator's truth rig: calibrating in the test would take
// longer than the e2e budget (60 s). docs/verify-and-check.md gives the same
// figures with a calibrated rig.
#include <ceres/ceres.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/core/rig_file.h"
#include "reconstruct/metrology/artifact.h"
#include "reconstruct/metrology/vdi2634.h"
#include "reconstruct/runtime.h"
#include "tests/sim_scene.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;
using Points = std::vector<Eigen::Vector3d>;

constexpr double kAgreementMm = 0.005;    // issue 6
constexpr double kMeanAbsErrorMm = 0.15;  // issue 5, two modules merged

// --- The independent fits. ---------------------------------------------------

struct SphereResidual {
  explicit SphereResidual(const Eigen::Vector3d& p) : p_(p) {}
  template <typename T>
  bool operator()(const T* c, const T* r, T* e) const {
    const T dx = T(p_.x()) - c[0], dy = T(p_.y()) - c[1], dz = T(p_.z()) - c[2];
    e[0] = ceres::sqrt(dx * dx + dy * dy + dz * dz) - r[0];
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& p) {
    return new ceres::AutoDiffCostFunction<SphereResidual, 1, 3, 1>(new SphereResidual(p));
  }
  Eigen::Vector3d p_;
};

struct Sphere {
  Eigen::Vector3d c;
  double r = 0;
  double Distance(const Eigen::Vector3d& p) const { return (p - c).norm() - r; }
};

// |p|^2 = 2 c.p + (r^2 - |c|^2): linear in (c, k), solved with SVD.
Sphere KasaFit(const Points& pts, const std::vector<int>& idx) {
  cv::Mat a(static_cast<int>(idx.size()), 4, CV_64F), b(static_cast<int>(idx.size()), 1, CV_64F), x;
  for (int i = 0; i < a.rows; ++i) {
    const Eigen::Vector3d& p = pts[idx[i]];
    a.at<double>(i, 0) = 2 * p.x(), a.at<double>(i, 1) = 2 * p.y(), a.at<double>(i, 2) = 2 * p.z();
    a.at<double>(i, 3) = 1;
    b.at<double>(i) = p.squaredNorm();
  }
  cv::solve(a, b, x, cv::DECOMP_SVD);
  Sphere s;
  s.c = Eigen::Vector3d(x.at<double>(0), x.at<double>(1), x.at<double>(2));
  s.r = std::sqrt(x.at<double>(3) + s.c.squaredNorm());
  return s;
}

Sphere CeresFit(const Points& pts, const std::vector<int>& idx, Sphere s) {
  ceres::Problem problem;
  for (int i : idx) problem.AddResidualBlock(SphereResidual::Create(pts[i]), nullptr, s.c.data(), &s.r);
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.function_tolerance = 1e-14;
  o.parameter_tolerance = 1e-14;
  o.gradient_tolerance = 1e-16;
  o.max_num_iterations = 100;
  ceres::Solver::Summary summary;
  ceres::Solve(o, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  return s;
}

// Drops floor(0.3% of n) points with the largest |residual|.
std::vector<int> ExcludeLargest(const std::vector<int>& idx, const std::function<double(int)>& residual) {
  std::vector<int> sorted = idx;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [&](int a, int b) { return std::abs(residual(a)) < std::abs(residual(b)); });
  sorted.resize(idx.size() - static_cast<size_t>(std::floor(0.003 * idx.size())));
  return sorted;
}

double RangeOf(const std::vector<int>& idx, const std::function<double(int)>& residual) {
  double lo = 1e300, hi = -1e300;
  for (int i : idx) lo = std::min(lo, residual(i)), hi = std::max(hi, residual(i));
  return hi - lo;
}

struct IndependentSphere {
  Sphere s;
  std::vector<int> set;   // the points within the band (and outside the cone)
  std::vector<int> used;  // after exclusion
  double form_mm = 0;     // range of the residuals
};

// The points within `band` of the sphere (and, for a ball bar, outside the
// cone of `cone_deg` about `towards`), iterated to a fixed point from
// `start`, then the 0.3% exclusion and a last fit.
IndependentSphere FitSphereIndependently(const Points& pts, Sphere start, double band,
                                         const Eigen::Vector3d* towards = nullptr, double cone_deg = 0) {
  Sphere s = start;
  std::vector<int> set;
  auto select = [&](const Sphere& sph, const Eigen::Vector3d* axis_to) {
    std::vector<int> out;
    const double cos_cone = std::cos(cone_deg * M_PI / 180);
    for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
      if (std::abs(sph.Distance(pts[i])) >= band) continue;
      if (axis_to && (pts[i] - sph.c).normalized().dot((*axis_to - sph.c).normalized()) > cos_cone) continue;
      out.push_back(i);
    }
    return out;
  };
  for (int it = 0; it < 20; ++it) {
    std::vector<int> next = select(s, towards);
    if (next == set) break;
    set = next;
    s = CeresFit(pts, set, KasaFit(pts, set));
  }
  IndependentSphere out;
  out.set = set;
  out.used = ExcludeLargest(set, [&](int i) { return s.Distance(pts[i]); });
  out.s = CeresFit(pts, out.used, s);
  out.form_mm = RangeOf(out.used, [&](int i) { return out.s.Distance(pts[i]); });
  return out;
}

struct Plane {
  Eigen::Vector3d n, mean;
  double Distance(const Eigen::Vector3d& p) const { return n.dot(p - mean); }
};

// The total-least-squares plane by SVD; also the in-plane principal axes.
Plane SvdPlane(const Points& pts, const std::vector<int>& idx, Eigen::Vector3d* u = nullptr,
               Eigen::Vector3d* v = nullptr) {
  Plane pl;
  pl.mean = Eigen::Vector3d::Zero();
  for (int i : idx) pl.mean += pts[i];
  pl.mean /= static_cast<double>(idx.size());
  Eigen::MatrixXd a(idx.size(), 3);
  for (size_t k = 0; k < idx.size(); ++k) a.row(k) = (pts[idx[k]] - pl.mean).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinV);
  pl.n = svd.matrixV().col(2);
  if (u) *u = svd.matrixV().col(0);
  if (v) *v = svd.matrixV().col(1);
  return pl;
}

// The smallest rectangle in the plane holding the points `idx` (a side
// along an edge of their convex hull, OpenCV's, by index): centre-relative
// extents along its sides u (the longer) and v.
struct Outline {
  Eigen::Vector3d u, v;
  double u0, u1, v0, v1;
  bool InsideEroded(const Eigen::Vector3d& d, double m) const {
    return d.dot(u) > u0 + m && d.dot(u) < u1 - m && d.dot(v) > v0 + m && d.dot(v) < v1 - m;
  }
};
Outline SmallestRectangle(const Points& pts, const std::vector<int>& idx, const Plane& pl) {
  const Eigen::Vector3d a = pl.n.unitOrthogonal(), b = pl.n.cross(a);
  std::vector<cv::Point2f> q;
  for (int i : idx)
    q.emplace_back(static_cast<float>((pts[i] - pl.mean).dot(a)), static_cast<float>((pts[i] - pl.mean).dot(b)));
  std::vector<int> hull;
  cv::convexHull(q, hull, false, false);
  Outline best{};
  double best_area = 1e300;
  for (size_t k = 0; k < hull.size(); ++k) {
    const Eigen::Vector3d s = (pts[idx[hull[(k + 1) % hull.size()]]] - pts[idx[hull[k]]]).normalized();
    const Eigen::Vector3d e1 = (s - s.dot(pl.n) * pl.n).normalized(), e2 = pl.n.cross(e1);
    double lo1 = 1e300, hi1 = -1e300, lo2 = 1e300, hi2 = -1e300;
    for (int h : hull) {
      const Eigen::Vector3d d = pts[idx[h]] - pl.mean;
      lo1 = std::min(lo1, d.dot(e1)), hi1 = std::max(hi1, d.dot(e1)), lo2 = std::min(lo2, d.dot(e2));
      hi2 = std::max(hi2, d.dot(e2));
    }
    if ((hi1 - lo1) * (hi2 - lo2) >= best_area) continue;
    best_area = (hi1 - lo1) * (hi2 - lo2);
    best = hi1 - lo1 >= hi2 - lo2 ? Outline{e1, e2, lo1, hi1, lo2, hi2} : Outline{e2, e1, lo2, hi2, lo1, hi1};
  }
  return best;
}

// The capture band verify uses for a figure with this MPE (vdi2634.h).
double CaptureBand(double mpe_mm) { return std::max(VerifyOptions{}.capture_band_mm, 2 * mpe_mm); }

// --- The test. ---------------------------------------------------------------

Eigen::Matrix4d ReadPose(const YAML::Node& rows) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows[r][c].as<double>();
  return m;
}

const ArtifactEvaluation& Print(const char* scene, const ArtifactEvaluation& e) {
  std::printf("%s: %d points, %d on the artifact, %d excluded; mean |e| %.4f mm, std %.4f mm;", scene, e.points_total,
              e.points_on_artifact, e.points_excluded, e.residual_mean_abs_mm, e.residual_std_mm);
  for (const Figure& f : e.figures) std::printf(" %s %+.4f mm", f.name.c_str(), f.value_mm);
  std::printf("\n");
  return e;
}

// Each test simulates only its own scene (ctest runs each in its own
// process), reconstructs it with the truth rig, and reads the truth.
class VerifyReconstruction : public ::testing::Test {
 protected:
  void TearDown() override { fs::remove_all(dir_); }
  Points Reconstruct(const std::string& scene) {
    dir_ = testing::SimulateOneScene(scene, 3, "verify_reconstruction_" + scene);
    const Rig rig = ReadRigFile(dir_ + "/truth/rig.yaml");
    const Runtime runtime(rig, RuntimeOptions{});
    const Reconstruction rec = runtime.Process(LoadCapture(dir_ + "/scenes/" + scene + "/active", rig), false);
    Points pts;
    for (const auto& p : rec.cloud.xyz_mm) pts.push_back(p.cast<double>());
    return pts;
  }
  Artifact ReadArtifact(const std::string& scene) { return ReadArtifactFile(dir_ + "/artifacts/" + scene + ".yaml"); }
  YAML::Node Objects(const std::string& scene) {
    return YAML::LoadFile(dir_ + "/truth/scenes/" + scene + "/object.yaml")["objects"];
  }
  std::string dir_;
};

TEST_F(VerifyReconstruction, SphereFiguresAgreeWithAnIndependentFit) {
  const Points pts = Reconstruct("sphere");
  const Artifact a = ReadArtifact("sphere");
  const ArtifactEvaluation ours = Print("sphere", EvaluateArtifact(a, pts, VerifyOptions{}, "sphere"));
  const YAML::Node obj = Objects("sphere")[0];
  const Sphere truth{ReadPose(obj["module0_from_object"]).block<3, 1>(0, 3), 0.5 * a.sphere_diameter_mm};
  const IndependentSphere mine =
      FitSphereIndependently(pts, truth, CaptureBand(std::max(a.mpe.probing_form_mm, a.mpe.probing_size_mm)));
  const double p_s = 2 * mine.s.r - a.sphere_diameter_mm;
  std::printf("independent: %zu points used; P_F %.4f mm, P_S %+.4f mm\n", mine.used.size(), mine.form_mm, p_s);
  ASSERT_EQ(ours.figures.size(), 2u);
  EXPECT_NEAR(ours.figures[0].value_mm, mine.form_mm, kAgreementMm);  // P_F
  EXPECT_NEAR(ours.figures[1].value_mm, p_s, kAgreementMm);           // P_S
  EXPECT_EQ(ours.points_on_artifact - ours.points_excluded, static_cast<int>(mine.used.size()));
  // Issue 5's accuracy. Measured (seed 3, truth rig): mean |e| 0.076 mm,
  // P_S -0.063 mm. P_F (the range, ~1.7 mm) is printed, not judged here: it
  // is set by the few worst mismatches on the flanks that the 0.3% rule
  // leaves, and verify's MPE (1.5 mm) judges it (it fails today).
  EXPECT_LT(ours.residual_mean_abs_mm, kMeanAbsErrorMm);
  EXPECT_LT(std::abs(ours.figures[1].value_mm), kMeanAbsErrorMm);
}

TEST_F(VerifyReconstruction, BallBarFigureAgreesWithAnIndependentFit) {
  const Points pts = Reconstruct("ballbar");
  const Artifact a = ReadArtifact("ballbar");
  const ArtifactEvaluation ours = Print("ballbar", EvaluateArtifact(a, pts, VerifyOptions{}, "ballbar"));
  const YAML::Node objs = Objects("ballbar");
  const double r = 0.5 * a.sphere_diameter_mm, band = CaptureBand(a.mpe.sphere_spacing_mm);
  Sphere ball[2] = {{ReadPose(objs[0]["module0_from_object"]).block<3, 1>(0, 3), r},
                    {ReadPose(objs[1]["module0_from_object"]).block<3, 1>(0, 3), r}};
  // Each ball without its shaft cone (60 degrees about the bar axis, as
  // vdi2634.h's VerifyOptions default), the axis from the other ball's fit;
  // alternate until both settle.
  IndependentSphere fit[2];
  for (int round = 0; round < 20; ++round) {
    const Eigen::Vector3d c0 = ball[0].c, c1 = ball[1].c;
    const std::vector<int> before[2] = {fit[0].set, fit[1].set};
    fit[0] = FitSphereIndependently(pts, ball[0], band, &c1, VerifyOptions{}.ballbar_shaft_cone_deg);
    fit[1] = FitSphereIndependently(pts, ball[1], band, &c0, VerifyOptions{}.ballbar_shaft_cone_deg);
    ball[0] = fit[0].s, ball[1] = fit[1].s;
    if (fit[0].set == before[0] && fit[1].set == before[1]) break;
  }
  const double sd = (ball[0].c - ball[1].c).norm() - a.center_distance_mm;
  for (int b = 0; b < 2; ++b) {  // where the error comes from: each ball against its truth
    const Eigen::Vector3d tc = ReadPose(objs[b]["module0_from_object"]).block<3, 1>(0, 3);
    std::printf("ball %d: fitted centre %.3f mm from the truth, radius %+.3f mm off\n", b, (ball[b].c - tc).norm(),
                ball[b].r - r);
  }
  std::printf("independent: %zu + %zu points used; SD %+.4f mm\n", fit[0].used.size(), fit[1].used.size(), sd);
  ASSERT_EQ(ours.figures.size(), 1u);
  EXPECT_NEAR(ours.figures[0].value_mm, sd, kAgreementMm);
  // Issue 5's accuracy, two modules merged. Measured (seed 3, truth rig)
  // after the line-index fix: mean |e| 0.101 mm, SD +0.069 mm, each ball's
  // centre within 0.11 mm of its truth (before it, a ball one grid period
  // off gave mean |e| 0.25 mm and SD +0.89 mm). A sphere-spacing error is a
  // difference of two centre errors, so it is held to the same 0.15 mm.
  EXPECT_LT(ours.residual_mean_abs_mm, kMeanAbsErrorMm);
  EXPECT_LT(std::abs(ours.figures[0].value_mm), kMeanAbsErrorMm);
}

TEST_F(VerifyReconstruction, PlateFigureAgreesWithAnIndependentFit) {
  const Points pts = Reconstruct("plate");
  const Artifact a = ReadArtifact("plate");
  const ArtifactEvaluation ours = Print("plate", EvaluateArtifact(a, pts, VerifyOptions{}, "plate"));
  // The face: of the plate's two large faces (object z = +-half thickness,
  // 8 mm apart: the capture band, 5 mm, holds one), the one with more points
  // within the band, as the largest consensus.
  const Eigen::Matrix4d m = ReadPose(Objects("plate")[0]["module0_from_object"]);
  const double band = CaptureBand(a.mpe.flatness_mm);
  const Eigen::Vector3d nz = m.block<3, 1>(0, 2), centre = m.block<3, 1>(0, 3);
  std::vector<int> face[2];
  for (int i = 0; i < static_cast<int>(pts.size()); ++i)
    for (int k = 0; k < 2; ++k)
      if (std::abs(nz.dot(pts[i] - centre) - (k ? 4.0 : -4.0)) < band) face[k].push_back(i);
  Plane pl = SvdPlane(pts, face[0].size() > face[1].size() ? face[0] : face[1]);
  // The points within the band of the plane, inside their outline eroded by
  // the edge margin (5 mm); the set and the plane iterated to a fixed point.
  const double margin = VerifyOptions{}.plate_edge_margin_mm;
  std::vector<int> inner;
  for (int it = 0; it < 20; ++it) {
    std::vector<int> set;
    for (int i = 0; i < static_cast<int>(pts.size()); ++i)
      if (std::abs(pl.Distance(pts[i])) < band) set.push_back(i);
    const Outline outline = SmallestRectangle(pts, set, pl);
    std::vector<int> next;
    for (int i : set)
      if (outline.InsideEroded(pts[i] - pl.mean, margin)) next.push_back(i);
    if (next == inner) break;
    inner = next;
    pl = SvdPlane(pts, inner);
  }
  const Plane inner_plane = SvdPlane(pts, inner);
  const std::vector<int> used = ExcludeLargest(inner, [&](int i) { return inner_plane.Distance(pts[i]); });
  const Plane final_plane = SvdPlane(pts, used);
  const double f = RangeOf(used, [&](int i) { return final_plane.Distance(pts[i]); });
  std::printf("independent: %zu points used; F %.4f mm\n", used.size(), f);
  ASSERT_EQ(ours.figures.size(), 1u);
  EXPECT_NEAR(ours.figures[0].value_mm, f, kAgreementMm);
  EXPECT_EQ(ours.points_on_artifact - ours.points_excluded, static_cast<int>(used.size()));
  // Issue 5's accuracy: mean |e| (measured 0.086 mm). F, a range over ~160k
  // points, is judged by verify's MPE (1.5 mm; measured 0.82 mm).
  EXPECT_LT(ours.residual_mean_abs_mm, kMeanAbsErrorMm);
  EXPECT_LT(ours.figures[0].value_mm, a.mpe.flatness_mm);
}

}  // namespace
}  // namespace stereorig
