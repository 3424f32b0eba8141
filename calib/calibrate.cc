#include "calib/calibrate.h"

#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <map>
#include <optional>
#include <set>

#include "calib/convergence.h"
#include "calib/core/atomic_file.h"
#include "calib/core/cameramodel_export.h"
#include "calib/core/input_error.h"
#include "calib/core/lens_plausibility.h"
#include "calib/core/rig_file.h"
#include "calib/json_writer.h"

namespace stereorig {

void TargetGeometry::Check(const std::string& where) const {
  if (corners_x < 2 || corners_y < 2) throw InputError(where, "the board needs at least 2x2 inner corners");
  if (!(square_size_mm > 0)) throw InputError(where, "square size must be > 0 mm");
  for (int i = 0; i < 6; ++i)
    if (!(back_from_front_sigma(i) >= 0)) throw InputError(where, "back_from_front sigma must be >= 0");
}

TargetGeometry TargetGeometryFromTarget(const Target& t) {
  TargetGeometry g;
  g.corners_x = t.corners_x();
  g.corners_y = t.corners_y();
  g.square_size_mm = t.square_size_mm();
  g.double_sided = t.double_sided();
  g.back_from_front = t.back_from_front();
  g.back_from_front_sigma = t.back_from_front_sigma();
  return g;
}

std::vector<int> CapturesWithDifferentFaces(const CalibrationInput& in, int left_camera, int right_camera) {
  std::map<int, Face> left_face;  // capture -> face the left camera saw
  for (const BoardObservation& o : in.observations)
    if (o.camera == left_camera && !o.corner_ids.empty()) left_face[o.capture] = o.face;
  std::set<int> out;
  for (const BoardObservation& o : in.observations) {
    if (o.camera != right_camera || o.corner_ids.empty()) continue;
    auto it = left_face.find(o.capture);
    if (it != left_face.end() && it->second != o.face) out.insert(o.capture);
  }
  return {out.begin(), out.end()};
}

void CalibrationOptions::Check() const {
  intrinsics.Check();
  stereo.Check();
  system.Check();
}

void ValidateInput(const CalibrationInput& in) {
  const std::string& src = in.source;
  in.target.Check(src + ": target");
  if (in.cameras.empty()) throw InputError(src, "no cameras in the layout");
  if (in.modules.empty()) throw InputError(src, "no modules in the layout");
  const int nc = static_cast<int>(in.cameras.size());
  std::vector<int> module_of(nc, -1);
  for (size_t k = 0; k < in.modules.size(); ++k) {
    const ModuleLayout& m = in.modules[k];
    const std::string w = src + ": layout module " + std::to_string(k) + " (" + m.name + ")";
    for (int c : {m.left_camera, m.right_camera}) {
      if (c < 0 || c >= nc) throw InputError(w, "names camera " + std::to_string(c) + ", which does not exist");
      if (module_of[c] >= 0)
        throw InputError(w,
                         "camera " + std::to_string(c) + " already belongs to module " + std::to_string(module_of[c]));
      module_of[c] = static_cast<int>(k);
    }
  }
  for (int c = 0; c < nc; ++c) {
    if (module_of[c] < 0) throw InputError(src, "camera " + std::to_string(c) + " belongs to no module");
    if (in.cameras[c].width_px <= 0 || in.cameras[c].height_px <= 0) {
      throw InputError(src, "camera " + std::to_string(c) + " has no imager size");
    }
  }
  std::set<std::pair<int, int>> seen;
  std::vector<int> views(nc, 0);
  for (const BoardObservation& o : in.observations) {
    const std::string w = src + ": capture " + std::to_string(o.capture) + ", camera " + std::to_string(o.camera);
    if (o.camera < 0 || o.camera >= nc) throw InputError(w, "no such camera in the layout");
    if (!seen.insert({o.capture, o.camera}).second) throw InputError(w, "observed twice");
    if (o.corner_ids.size() != o.q_px.size()) throw InputError(w, "corner ids and pixels differ in number");
    std::set<int> ids;
    const CameraImager& cs = in.cameras[o.camera];
    for (size_t i = 0; i < o.corner_ids.size(); ++i) {
      const int id = o.corner_ids[i];
      if (id < 0 || id >= in.target.num_corners()) {
        throw InputError(w, "corner id " + std::to_string(id) + " is not on the " +
                                std::to_string(in.target.corners_x) + "x" + std::to_string(in.target.corners_y) +
                                " board");
      }
      if (!ids.insert(id).second) throw InputError(w, "corner id " + std::to_string(id) + " appears twice");
      const Eigen::Vector2d& q = o.q_px[i];
      if (!q.allFinite() || q.x() < -0.5 || q.y() < -0.5 || q.x() > cs.width_px - 0.5 || q.y() > cs.height_px - 0.5) {
        char b[200];
        std::snprintf(b, sizeof b, "corner at (%.1f, %.1f) px lies outside the %dx%d imager (wrong image size?)", q.x(),
                      q.y(), cs.width_px, cs.height_px);
        throw InputError(w, b);
      }
    }
    if (o.face == Face::kBack && !in.target.double_sided) {
      throw InputError(w, "sees the back face of a one-sided target");
    }
    const int k = module_of[o.camera];
    const ModuleLayout& m = in.modules[k];
    if (m.face && *m.face != o.face) {
      throw InputError(w, std::string("face seen by the wrong module: module ") + std::to_string(k) + " (" + m.name +
                              ") sees only the " + FaceName(*m.face) + " face, but this view is of the " +
                              FaceName(o.face) + " face");
    }
    if (!o.corner_ids.empty()) ++views[o.camera];
  }
  for (int c = 0; c < nc; ++c) {
    if (views[c] == 0) {
      throw InputError(src, "camera " + std::to_string(c) + " (" + in.cameras[c].name + ") never sees the board");
    }
  }
}

namespace {

std::string NowUtc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

void Progress(bool on, const std::string& msg) {
  if (on) std::cerr << "calibrate: " << msg << std::endl;
}

// What stages 1 and 2 rejected, for stage 3 to leave out (SystemExclusions):
//  - the views stage 1 dropped (too few corners, collinear, no PnP seed, or
//    left without a determined board pose by the outlier rejection), and
//    those stage 2 left out for the latter (StereoReport::views_left_out:
//    a capture whose left and right images were swapped, its corners
//    otherwise back in stage 3 at 149 px, and the rig refused);
//  - the corners mrcal's outlier rejection flagged in stage 1, the camera's
//    own solve: one that does not fit its camera's intrinsics, with a board
//    pose of its own per view, has no business steering the joint solve;
//  - and those it flagged in stage 2, the module's joint solve: there the
//    board pose is shared by the two cameras, as in stage 3 (which shares it
//    among every module), so a corner inconsistent with its partner camera
//    is the same inconsistency stage 3 would meet. Stage 2 re-marks every
//    corner from weight 1, so the two sets differ and are united;
//  - the captures stage 2 set aside for a module (its two cameras saw
//    different faces): its list, so that stages 2 and 3 cannot disagree.
// A flagged corner is one the view saw whose pool weight is <= 0 after the
// solve (an unseen corner is -1 from the start, and not in the view).
SystemExclusions EarlierStageVerdicts(const CalibrationInput& in, const std::vector<IntrinsicsResult>& stage1,
                                      const std::vector<StereoResult>& stage2) {
  SystemExclusions ex;
  const int n = in.target.num_corners();
  std::map<std::pair<int, int>, const BoardObservation*> obs;  // (capture, camera)
  for (const BoardObservation& o : in.observations)
    if (!o.corner_ids.empty()) obs[{o.capture, o.camera}] = &o;
  // Corners `o` saw whose weight in the pool block `block` is <= 0.
  auto mark = [&](const BoardObservation& o, const mrcal_point3_t* block) {
    for (int id : o.corner_ids)
      if (block[id].z <= 0) ex.corners.insert({o.capture, o.camera, id});
  };
  for (size_t c = 0; c < stage1.size(); ++c) {
    const IntrinsicsResult& s1 = stage1[c];
    const int camera = s1.report.camera;
    std::set<int> used(s1.captures.begin(), s1.captures.end());
    for (const auto& [key, o] : obs)
      if (key.second == camera && !used.count(key.first)) ex.views.insert(key);
    for (size_t k = 0; k < s1.captures.size(); ++k) {
      auto it = obs.find({s1.captures[k], camera});
      if (it != obs.end()) mark(*it->second, &s1.problem.pool[k * n]);
    }
  }
  for (size_t m = 0; m < stage2.size(); ++m) {
    const StereoResult& s2 = stage2[m];
    for (int c : s2.report.different_face_captures) ex.module_captures.insert({c, static_cast<int>(m)});
    for (const std::pair<int, int>& view : s2.report.views_left_out) ex.views.insert(view);
    const int cams[2] = {in.modules[m].left_camera, in.modules[m].right_camera};
    for (int o = 0; o < s2.problem.num_observations(); ++o) {
      const mrcal_observation_board_t& ob = s2.problem.observations[o];
      auto it = obs.find({s2.captures[ob.iframe], cams[ob.icam.intrinsics]});
      if (it != obs.end()) mark(*it->second, &s2.problem.pool[o * n]);
    }
  }
  return ex;
}

// "" if stage 3's back_from_front is within its file's sigma (or was
// held), else the line refusing the file. The bound is the same plate's
// over the axes refined (SamePlateChiSquare(axes); an axis whose sigma is 0
// is held and not judged): a right file's chi-square is at most as wide as
// chi-square with that many degrees of freedom (SystemReport), so fewer
// than 3 in 1000 right files are refused; a thickness typed in metres (tz
// 0.005 for 5 mm, the file's sigma 0.01 mm) reads ~70000.
std::string WrongPlateProblem(const PlateDifference& d) {
  if (d.SamePlate()) return "";
  char b[400];
  std::snprintf(b, sizeof b,
                "back_from_front: stage 3 moved its %s by %+.4f %s, against a sigma of %.4f %s from the file's "
                "back_from_front_sigma (with its rotation's lever arm on a translation) (chi-square %.1f over the %d "
                "axes it refined, above %.2f, which a right file exceeds fewer than 3 times in 1000)",
                PlateAxisName(d.worst), d.worst_off, PlateAxisUnit(d.worst), d.worst_sigma, PlateAxisUnit(d.worst),
                d.chi_square, d.axes, d.Bound());
  return std::string(b) +
         ": the target file's back_from_front is not this plate's: measure the plate again or fix "
         "the file";
}

}  // namespace

CalibrationResult Calibrate(const CalibrationInput& in, const CalibrationOptions& options) {
  options.Check();
  ValidateInput(in);
  const int nc = static_cast<int>(in.cameras.size());
  const int M = static_cast<int>(in.modules.size());
  std::vector<std::vector<const BoardObservation*>> by_camera(nc);
  for (const BoardObservation& o : in.observations)
    if (!o.corner_ids.empty()) by_camera[o.camera].push_back(&o);

  CalibrationResult result{Rig(), {}, {}, {}, {}};
  CalibrationReport& rep = result.report;
  rep.source = in.source;
  rep.num_modules = M;
  rep.capture_names = in.capture_names;
  rep.max_rms_px = options.intrinsics.max_rms_px;

  // Stage 1.
  for (int c = 0; c < nc; ++c) {
    Progress(options.progress, "stage 1: intrinsics of camera " + std::to_string(c) + " (" +
                                   std::to_string(by_camera[c].size()) + " views)");
    result.stage1.push_back(CalibrateIntrinsics(
        c, in.cameras[c], in.target, by_camera[c], options.intrinsics, in.source,
        [&](const std::string& message) { Progress(options.progress, message); }, in.capture_names));
    rep.intrinsics.push_back(result.stage1.back().report);
  }
  // A camera that did not converge ends the calibration here: stages 2 and 3
  // would start from its wrong lens, and could refuse the captures for it
  // ("too few views shared") before the convergence check named the cause.
  rep.not_converged = NotConvergedProblem(rep, rep.max_rms_px);
  if (!rep.not_converged.empty()) return result;
  // Stage 2.
  std::vector<ModuleCameras> modules;
  for (int k = 0; k < M; ++k) {
    const ModuleLayout& m = in.modules[k];
    Progress(options.progress, "stage 2: stereo extrinsics of module " + std::to_string(k));
    result.stage2.push_back(CalibrateStereo(k, m, result.stage1[m.left_camera], result.stage1[m.right_camera],
                                            by_camera[m.left_camera], by_camera[m.right_camera], in, options.stereo,
                                            options.intrinsics));
    rep.stereo.push_back(result.stage2.back().report);
    const StereoResult& s = result.stage2.back();
    modules.push_back({m.left_camera, m.right_camera, s.left, s.right, s.right_from_left,
                       s.report.left.intrinsics_covariance, s.report.right.intrinsics_covariance,
                       s.report.intrinsics_cross_covariance});
  }
  // Stage 3.
  std::vector<Pose> module0_from_module(M);
  if (M > 1) {
    Progress(options.progress, "stage 3: Horn + bundle adjustment over " + std::to_string(M) + " modules");
    double s2 = 0;
    for (const StereoReport& s : rep.stereo) s2 += s.rms_px * s.rms_px;
    result.stage3 = CalibrateSystem(in, modules, std::sqrt(s2 / rep.stereo.size()), options.system,
                                    EarlierStageVerdicts(in, result.stage1, result.stage2));
    modules = result.stage3.modules;
    module0_from_module = result.stage3.module0_from_module;
    rep.system = result.stage3.report;
    if (const std::string w = HornOnlyWarning(rep.system); !w.empty()) rep.warnings.push_back(w);
  } else {
    result.stage3.module0_from_module = module0_from_module;
    result.stage3.module0_from_module_horn = module0_from_module;
    result.stage3.modules = modules;
  }

  rep.not_converged = NotConvergedProblem(rep, rep.max_rms_px);
  // The plate is judged only by a stage 3 that converged: one that did not
  // moves back_from_front with everything else (a capture whose module 1
  // images were another's moved its tx 0.2 mm, and the target file was
  // blamed).
  if (M > 1 && rep.not_converged.empty()) rep.wrong_plate = WrongPlateProblem(rep.system.back_from_front_vs_file);

  // The rig.
  std::vector<Camera> cameras(nc, Camera("LENSMODEL_PINHOLE", {1, 1, 0, 0}, 1, 1));
  std::vector<std::string> names(nc);
  std::vector<StereoModule> rig_modules;
  for (int k = 0; k < M; ++k) {
    cameras[modules[k].left_camera] = modules[k].left;
    cameras[modules[k].right_camera] = modules[k].right;
    rig_modules.push_back(
        {in.modules[k].name, modules[k].left_camera, modules[k].right_camera, modules[k].right_from_left});
  }
  for (int c = 0; c < nc; ++c) names[c] = in.cameras[c].name;
  result.rig = Rig(std::move(cameras), std::move(names), std::move(rig_modules), module0_from_module);
  Provenance& pv = result.rig.provenance();
  pv.tool = std::string("stereorig ") + STEREORIG_VERSION;
  pv.date_utc = NowUtc();
  pv.input = in.source;
  {  // The board as calibrated: stereorig check measures with it (calib/check/check_target.h).
    CalibrationTarget& t = pv.target.emplace();
    t.corners_x = in.target.corners_x;
    t.corners_y = in.target.corners_y;
    t.square_size_mm = in.target.square_size_mm;
    t.double_sided = in.target.double_sided;
    t.back_from_front_file = in.target.back_from_front;
    t.back_from_front_sigma_file = in.target.back_from_front_sigma;
    t.back_from_front = M > 1 ? rep.system.back_from_front : in.target.back_from_front;
  }
  // Keys as docs/formats.md fixes them (stereorig check reads them).
  for (const IntrinsicsReport& r : rep.intrinsics) {
    pv.residuals["cam" + std::to_string(r.camera) + "_rms_px"] = r.rms_px;
    for (const PixelUncertainty& u : r.uncertainty)
      if (u.where == "centre")
        pv.uncertainties["cam" + std::to_string(r.camera) + "_projection_center_px"] = u.rms_stdev_px;
  }
  for (const StereoReport& s : rep.stereo) {
    pv.residuals["module" + std::to_string(s.module) + "_stereo_rms_px"] = s.rms_px;
    pv.residuals["module" + std::to_string(s.module) + "_rectified_row_rms_px"] = s.rectified_row_rms_px;
  }
  if (M > 1) {
    pv.residuals["rig_rms_px"] = rep.system.refined_reprojection_rms_px;
    pv.residuals["rig_horn_only_rms_px"] = rep.system.horn_reprojection_rms_px;
    for (const STransformSigma& s : rep.system.sigma) {
      const std::string k = "S_0_" + std::to_string(s.module);
      pv.uncertainties[k + "_translation_mm"] = s.translation_mm.norm();
      pv.uncertainties[k + "_rotation_deg"] = s.rotation_deg.norm();
    }
  }
  return result;
}

namespace {

// names: capture index -> folder name (CalibrationReport::capture_names).
void WriteIntrinsics(JsonWriter& j, const IntrinsicsReport& r, const std::map<int, std::string>& names) {
  j.BeginObject();
  j.Int("camera", r.camera).String("name", r.camera_name).String("lensmodel", r.lensmodel);
  j.Int("views", r.num_views).Int("views_dropped", r.num_views_dropped).Int("corners", r.num_corners);
  j.Int("outliers", r.num_outliers).Number("rms_px", r.rms_px).Number("observed_sigma_px", r.observed_sigma_px);
  j.Number("max_tilt_deg", r.max_tilt_deg);
  j.Int("seeds_tried", r.seeds_tried);
  j.BeginArray("worst_views");
  for (const ViewResidual& v : r.worst_views) {
    j.BeginObject().Int("capture", v.capture);
    if (auto it = names.find(v.capture); it != names.end()) j.String("capture_name", it->second);
    j.Number("rms_px", v.rms_px).Int("corners", v.num_corners).EndObject();
  }
  j.EndArray();
  j.BeginObject("coverage").Int("cells_x", r.coverage_cells_x).Int("cells_y", r.coverage_cells_y);
  j.Number("fraction", r.coverage_fraction).BeginArray("counts");
  for (int c : r.coverage) j.Int(c);
  j.EndArray().EndObject();
  j.BeginObject("projection_uncertainty").Number("range_mm", r.uncertainty_range_mm).BeginArray("at");
  for (const PixelUncertainty& u : r.uncertainty) {
    j.BeginObject().String("where", u.where).Numbers("q_px", {u.q_px.x(), u.q_px.y()});
    j.Number("sigma_px", u.rms_stdev_px).Number("worst_direction_sigma_px", u.worst_direction_stdev_px).EndObject();
  }
  j.EndArray().EndObject();
  j.Numbers("intrinsics", r.intrinsics).Numbers("intrinsics_sigma", r.intrinsics_sigma);
  j.EndObject();
}

void WritePose(JsonWriter& j, const std::string& key, const Pose& p) {
  const Eigen::Vector3d r = p.RotationVector() * 180.0 / M_PI;
  j.BeginObject(key).Numbers("rotation_vector_deg", {r.x(), r.y(), r.z()});
  j.Numbers("translation_mm", {p.translation_mm().x(), p.translation_mm().y(), p.translation_mm().z()}).EndObject();
}

}  // namespace

std::string CalibrationReport::CaptureName(int capture) const {
  const auto it = capture_names.find(capture);
  return it != capture_names.end() ? it->second : std::to_string(capture);
}

std::string CalibrationReport::ToJson() const {
  JsonWriter j;
  j.BeginObject().String("source", source).Int("modules", num_modules);
  // The verdict calibrate acted on: a report beside no new rig file says why.
  j.BeginObject("convergence").Number("max_rms_px", max_rms_px).String("not_converged", not_converged).EndObject();
  j.BeginArray("warnings");
  for (const std::string& w : warnings) j.String("", w);
  j.EndArray();
  j.BeginArray("stage1_intrinsics");
  for (const IntrinsicsReport& r : intrinsics) WriteIntrinsics(j, r, capture_names);
  j.EndArray();
  j.BeginArray("stage2_stereo");
  for (const StereoReport& s : stereo) {
    j.BeginObject().Int("module", s.module).String("name", s.module_name);
    j.Int("shared_views", s.num_shared_views).Int("frames", s.num_frames).Number("rms_px", s.rms_px);
    j.BeginArray("different_face_captures");
    for (int c : s.different_face_captures) j.Int(c);
    j.EndArray();
    if (!capture_names.empty()) {  // the same captures by folder name, in the same order
      j.BeginArray("different_face_capture_names");
      for (int c : s.different_face_captures) j.String("", CaptureName(c));
      j.EndArray();
    }
    j.Int("outliers", s.num_outliers).Number("baseline_mm", s.baseline_mm).Number("rotation_deg", s.rotation_deg);
    j.Numbers("right_from_left_rotation_vector_deg",
              {s.right_from_left_rotation_vector_deg.x(), s.right_from_left_rotation_vector_deg.y(),
               s.right_from_left_rotation_vector_deg.z()});
    j.Numbers("right_from_left_translation_mm",
              {s.right_from_left_translation_mm.x(), s.right_from_left_translation_mm.y(),
               s.right_from_left_translation_mm.z()});
    j.String("covariance", s.covariance_status);  // "ok", or why the sigmas are null
    j.Number("baseline_sigma_mm", s.baseline_sigma_mm).Number("rotation_sigma_deg", s.rotation_sigma_deg);
    j.Numbers("right_from_left_rotation_vector_sigma_deg",
              {s.right_from_left_rotation_vector_sigma_deg.x(), s.right_from_left_rotation_vector_sigma_deg.y(),
               s.right_from_left_rotation_vector_sigma_deg.z()});
    j.Numbers("right_from_left_translation_sigma_mm",
              {s.right_from_left_translation_sigma_mm.x(), s.right_from_left_translation_sigma_mm.y(),
               s.right_from_left_translation_sigma_mm.z()});
    j.Number("rectified_row_rms_px", s.rectified_row_rms_px).Number("rectified_row_max_px", s.rectified_row_max_px);
    j.Int("corner_pairs", s.num_corner_pairs);
    j.BeginArray("cameras_joint_solve");
    WriteIntrinsics(j, s.left, capture_names);
    WriteIntrinsics(j, s.right, capture_names);
    j.EndArray();
    j.EndObject();
  }
  j.EndArray();
  if (num_modules > 1 && !stereo.empty()) {  // stage 3 ran (not after a stage 1 that did not converge)
    const SystemReport& s = system;
    j.BeginObject("stage3_system").Int("captures", s.num_captures).Int("corner_residuals", s.num_residual_corners);
    j.Int("skipped_views", s.num_skipped_views).Int("skipped_view_corners", s.num_skipped_view_corners);
    j.Int("skipped_outlier_corners", s.num_skipped_outlier_corners);
    j.BeginArray("spanning_tree");
    for (const auto& [a, b] : s.spanning_tree) {
      j.BeginObject().Int("parent", a).Int("child", b).Number("horn_rms_mm", s.horn_rms_mm.at({a, b})).EndObject();
    }
    j.EndArray();
    j.BeginObject("horn_only")
        .Number("reprojection_rms_px", s.horn_reprojection_rms_px)
        .String("solver_problem", s.horn_only_solver_problem)
        .BeginArray("module0_from_module");
    for (const Pose& p : s.module0_from_module_horn) {
      j.BeginObject();
      WritePose(j, "pose", p);
      j.EndObject();
    }
    j.EndArray().EndObject();
    j.BeginObject("refined")
        .Number("reprojection_rms_px", s.refined_reprojection_rms_px)
        .Number("median_corner_residual_px", s.refined_median_corner_residual_px)
        .BeginArray("capture_rms");
    for (const SystemReport::CaptureRms& c : s.refined_capture_rms) {
      j.BeginObject().Int("capture", c.capture);
      if (auto it = capture_names.find(c.capture); it != capture_names.end()) j.String("capture_name", it->second);
      j.Number("rms_px", c.rms_px).Int("corners", c.corners).EndObject();
    }
    j.EndArray().BeginArray("camera_residuals");
    for (const SystemReport::CameraResiduals& c : s.refined_camera_residuals) {
      const Stage3CameraLimits l = Stage3CameraLimitsOf(*this, c.camera, max_rms_px);
      j.BeginObject()
          .Int("camera", c.camera)
          .Int("corners", c.corners)
          .Number("rms_px", c.rms_px)
          .Number("median_px", c.median_px)
          .Number("p90_px", c.p90_px)
          .Number("stage2_sigma_px", l.sigma_px)
          .Number("median_limit_px", l.median_px)
          .Number("p90_limit_px", l.p90_px)
          .EndObject();
    }
    j.EndArray().BeginArray("module0_from_module");
    for (const Pose& p : s.module0_from_module) {
      j.BeginObject();
      WritePose(j, "pose", p);
      j.EndObject();
    }
    j.EndArray().EndObject();
    j.String("covariance", s.covariance_status).String("sigma_conditional_on", s.sigma_conditional_on);
    j.BeginArray("sigma_S_0_k");
    for (const STransformSigma& x : s.sigma) {
      j.BeginObject().Int("module", x.module);
      j.Numbers("rotation_deg", {x.rotation_deg.x(), x.rotation_deg.y(), x.rotation_deg.z()});
      j.Numbers("translation_mm", {x.translation_mm.x(), x.translation_mm.y(), x.translation_mm.z()}).EndObject();
    }
    j.EndArray();
    // The refined values the rig file holds, with their 1 sigma (keys as stage 2's).
    j.BeginArray("refined_stereo");
    for (const RefinedStereoSigma& x : s.stereo_sigma) {
      j.BeginObject().Int("module", x.module);
      j.Number("baseline_mm", x.baseline_mm).Number("baseline_sigma_mm", x.baseline_sigma_mm);
      j.Number("rotation_deg", x.rotation_deg).Number("rotation_sigma_deg", x.rotation_sigma_deg);
      j.Numbers("right_from_left_rotation_vector_deg",
                {x.rotation_vector_deg.x(), x.rotation_vector_deg.y(), x.rotation_vector_deg.z()});
      j.Numbers("right_from_left_rotation_vector_sigma_deg",
                {x.rotation_vector_sigma_deg.x(), x.rotation_vector_sigma_deg.y(), x.rotation_vector_sigma_deg.z()});
      j.Numbers("right_from_left_translation_mm", {x.translation_mm.x(), x.translation_mm.y(), x.translation_mm.z()});
      j.Numbers("right_from_left_translation_sigma_mm",
                {x.translation_sigma_mm.x(), x.translation_sigma_mm.y(), x.translation_sigma_mm.z()});
      j.EndObject();
    }
    j.EndArray().BeginArray("refined_intrinsics");
    for (const RefinedIntrinsicsSigma& x : s.intrinsics_sigma) {
      j.BeginObject().Int("camera", x.camera).Numbers("intrinsics", x.intrinsics);
      j.Numbers("intrinsics_sigma", x.sigma).EndObject();
    }
    j.EndArray();
    WritePose(j, "back_from_front_refined", s.back_from_front);
    j.Number("back_from_front_change_deg", s.back_from_front_change_deg);
    j.Number("back_from_front_change_mm", s.back_from_front_change_mm);
    j.Number("back_from_front_chi_square", s.back_from_front_vs_file.chi_square);
    j.Int("back_from_front_axes", s.back_from_front_vs_file.axes);
    j.Number("back_from_front_chi_square_bound", s.back_from_front_vs_file.Bound()).String("wrong_plate", wrong_plate);
    j.String("solver", s.solver_summary).String("solver_problem", s.solver_problem);
    j.Int("max_iterations", s.max_iterations).EndObject();
  }
  j.EndObject();
  return j.str() + "\n";
}

namespace {

// Each camera's model as DIR/<camera name>.cameramodel, added to *outputs;
// returns their paths.
std::vector<std::string> AddCameramodels(const Rig& rig, const std::string& dir, AtomicOutputSet* outputs) {
  std::vector<std::string> paths;
  for (int c = 0; c < rig.num_cameras(); ++c) {
    paths.push_back(dir + "/" + rig.camera_names()[c] + ".cameramodel");
    outputs->Add(paths.back(), CameramodelText(rig.camera(c), rig.CamFromReference(c)));
  }
  return paths;
}

}  // namespace

std::vector<std::string> ExportCameramodels(const Rig& rig, const std::string& dir) {
  AtomicOutputSet outputs;
  std::vector<std::string> paths = AddCameramodels(rig, dir, &outputs);
  outputs.Commit();
  return paths;
}

namespace {

// Appends one printf-formatted line (the compiler checks the format).
__attribute__((format(printf, 2, 3))) void AppendLine(std::string* out, const char* fmt, ...) {
  char b[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(b, sizeof b, fmt, args);
  va_end(args);
  *out += b;
  *out += '\n';
}

}  // namespace

std::string SummaryText(const CalibrationReport& rep) {
  std::string out;
  AppendLine(&out, "stage 1: intrinsics per camera");
  for (const IntrinsicsReport& r : rep.intrinsics) {
    double worst_corner = 0;
    double centre = 0;
    for (const PixelUncertainty& u : r.uncertainty) {
      if (u.where == "centre") {
        centre = u.rms_stdev_px;
      } else {
        worst_corner = std::max(worst_corner, u.rms_stdev_px);
      }
    }
    AppendLine(&out,
               "  %s (%s): %d views, %d corners, rms %.3f px, %d outliers, coverage %.0f%%, 1-sigma projection %.3f px "
               "centre / %.3f px worst corner (at %.0f mm)",
               r.camera_name.c_str(), r.lensmodel.c_str(), r.num_views, r.num_corners, r.rms_px, r.num_outliers,
               100.0 * r.coverage_fraction, centre, worst_corner, r.uncertainty_range_mm);
    if (r.intrinsics.size() >= 4 && r.intrinsics_sigma.size() == r.intrinsics.size()) {
      const auto& v = r.intrinsics;
      const auto& e = r.intrinsics_sigma;
      AppendLine(&out, "    fx %.2f +- %.2f, fy %.2f +- %.2f, cx %.2f +- %.2f, cy %.2f +- %.2f px (1 sigma)", v[0],
                 e[0], v[1], e[1], v[2], e[2], v[3], e[3]);
    }
    if (r.seeds_tried > 1) {
      AppendLine(&out, "    solved from each of %d pinhole seeds, the lowest rms kept: the first did not converge",
                 r.seeds_tried);
    }
    if (!r.worst_views.empty()) {
      AppendLine(&out, "    worst view: capture %s, rms %.3f px", rep.CaptureName(r.worst_views[0].capture).c_str(),
                 r.worst_views[0].rms_px);
    }
  }
  if (rep.stereo.empty() && !rep.not_converged.empty()) {
    AppendLine(&out, "stages 2 and 3 not run: stage 1 did not converge (rms over %g px)", rep.max_rms_px);
    return out;
  }
  AppendLine(&out, "stage 2: stereo extrinsics per module");
  for (const StereoReport& s : rep.stereo) {
    // A covariance that failed gives no sigma, said so (it printed +- 0.0000).
    char figures[160];
    if (s.covariance_status == "ok")
      std::snprintf(figures, sizeof figures, "baseline %.4f +- %.4f mm, rotation %.4f +- %.4f deg (1 sigma)",
                    s.baseline_mm, s.baseline_sigma_mm, s.rotation_deg, s.rotation_sigma_deg);
    else
      std::snprintf(figures, sizeof figures, "baseline %.4f mm, rotation %.4f deg (no sigma)", s.baseline_mm,
                    s.rotation_deg);
    AppendLine(&out,
               "  %s: %s, rms %.3f px, %d outliers, rectified-row error %.3f px rms (max %.3f) over %d corner pairs, "
               "%d shared views",
               s.module_name.c_str(), figures, s.rms_px, s.num_outliers, s.rectified_row_rms_px, s.rectified_row_max_px,
               s.num_corner_pairs, s.num_shared_views);
    if (s.covariance_status != "ok") AppendLine(&out, "    no sigma: %s", s.covariance_status.c_str());
    if (!s.different_face_captures.empty()) {
      std::string list;
      for (size_t i = 0; i < s.different_face_captures.size(); ++i) {
        if (i == 20) {
          list += ", ...";  // the report lists them all
          break;
        }
        list += (i ? ", " : "") + rep.CaptureName(s.different_face_captures[i]);
      }
      AppendLine(&out,
                 "    %zu capture(s) set aside in stage 2%s: the module's two cameras saw different faces (the "
                 "board's plane between them, or a face misread): %s",
                 s.different_face_captures.size(), rep.num_modules > 1 ? " and 3" : "", list.c_str());
    }
  }
  if (rep.num_modules > 1) {
    const SystemReport& s = rep.system;
    AppendLine(&out, "stage 3: the S matrix (%d captures, %d corner residuals)", s.num_captures,
               s.num_residual_corners);
    if (s.num_skipped_views > 0 || s.num_skipped_outlier_corners > 0) {
      AppendLine(
          &out,
          "  left out as stages 1-2 judged: %d view(s) stage 1 or 2 dropped (%d corners), %d outlier corner(s) of "
          "stage 1 or 2",
          s.num_skipped_views, s.num_skipped_view_corners, s.num_skipped_outlier_corners);
    }
    AppendLine(&out, "  reprojection rms: Horn only %.3f px, refined %.3f px", s.horn_reprojection_rms_px,
               s.refined_reprojection_rms_px);
    if (!s.horn_only_solver_problem.empty())
      AppendLine(&out, "  (the Horn-only rms is %s: %s)",
                 std::isfinite(s.horn_reprojection_rms_px) ? "where its solve stopped" : "not a number",
                 s.horn_only_solver_problem.c_str());
    if (!s.refined_capture_rms.empty()) {
      const SystemReport::CaptureRms& w = s.refined_capture_rms[0];
      AppendLine(&out, "  worst capture: %s, rms %.3f px over %d corners", rep.CaptureName(w.capture).c_str(), w.rms_px,
                 w.corners);
    }
    // Each camera against the noise stage 2 measured on it (calib/convergence.h).
    for (const SystemReport::CameraResiduals& c : s.refined_camera_residuals) {
      const Stage3CameraLimits l = Stage3CameraLimitsOf(rep, c.camera, rep.max_rms_px);
      char excess[80];
      if (l.floor_sets_them)
        std::snprintf(excess, sizeof excess, "the floor %.3f px, %g x --max-rms-px", l.floor_px,
                      kStage3ExcessFloorOfLimit);
      else
        std::snprintf(excess, sizeof excess, "as much again");
      AppendLine(&out,
                 "  camera %d: corner distances median %.3f px, 90th percentile %.3f px (limits %.3f, %.3f px from its "
                 "stage 2 noise %.3f px and %s)",
                 c.camera, c.median_px, c.p90_px, l.median_px, l.p90_px, l.sigma_px, excess);
    }
    for (size_t k = 1; k < s.module0_from_module.size(); ++k) {
      const Pose d = s.module0_from_module_horn[k].Inverse() * s.module0_from_module[k];
      const Eigen::Vector3d& t = s.module0_from_module[k].translation_mm();
      AppendLine(&out, "  S[0][%zu]: t = (%.3f, %.3f, %.3f) mm; refined moved it %.4f deg, %.4f mm from Horn", k, t.x(),
                 t.y(), t.z(), d.AngleDeg(), d.DistanceMm());
    }
    for (const STransformSigma& x : s.sigma) {
      AppendLine(&out, "  1 sigma S[0][%d]: rotation (%.4f, %.4f, %.4f) deg, translation (%.4f, %.4f, %.4f) mm",
                 x.module, x.rotation_deg.x(), x.rotation_deg.y(), x.rotation_deg.z(), x.translation_mm.x(),
                 x.translation_mm.y(), x.translation_mm.z());
    }
    if (s.sigma.empty()) AppendLine(&out, "  1 sigma of S: %s", s.covariance_status.c_str());
    if (!s.sigma.empty() && !s.sigma_conditional_on.empty())
      AppendLine(&out, "  (conditional on %s)", s.sigma_conditional_on.c_str());
    for (const RefinedStereoSigma& x : s.stereo_sigma) {
      AppendLine(&out, "  refined module %d: baseline %.4f +- %.4f mm, rotation %.4f +- %.4f deg (1 sigma)", x.module,
                 x.baseline_mm, x.baseline_sigma_mm, x.rotation_deg, x.rotation_sigma_deg);
    }
    for (const RefinedIntrinsicsSigma& x : s.intrinsics_sigma) {
      const auto& v = x.intrinsics;
      const auto& e = x.sigma;
      AppendLine(&out, "  refined camera %d: fx %.2f +- %.2f, fy %.2f +- %.2f, cx %.2f +- %.2f, cy %.2f +- %.2f px",
                 x.camera, v[0], e[0], v[1], e[1], v[2], e[2], v[3], e[3]);
    }
    AppendLine(&out, "  back_from_front refined: moved %.4f deg, %.4f mm from the measured",
               s.back_from_front_change_deg, s.back_from_front_change_mm);
    if (!rep.wrong_plate.empty()) AppendLine(&out, "  REFUSED: %s", rep.wrong_plate.c_str());
    if (!rep.not_converged.empty())
      AppendLine(&out, "  not judged against the target file's back_from_front: %s",  // "stage K did not converge"
                 rep.not_converged.substr(0, rep.not_converged.find(':')).c_str());
  }
  return out;
}

void WriteCalibrationOutputs(const CalibrationResult& result, const std::string& rig_path,
                             const std::string& report_path, const std::string& cameramodels_dir) {
  // A solve that did not converge is named first: its lenses may well be
  // implausible too, but its RMS says which stage failed.
  if (!result.report.not_converged.empty()) {
    WriteFileAtomically(report_path, result.report.ToJson());
    throw InputError(rig_path, "not written: " + result.report.not_converged + "; the report is in " + report_path);
  }
  if (!result.report.wrong_plate.empty()) {
    WriteFileAtomically(report_path, result.report.ToJson());
    const std::optional<CalibrationTarget>& board = result.rig.provenance().target;
    throw InputError(board && !board->file.empty() ? board->file : "the target file",
                     result.report.wrong_plate + "; " + rig_path + " not written; the report is in " + report_path);
  }
  // A rig file its readers would refuse (ReadRigFile checks every lens) is
  // not written: a solve that diverged says so now, not at the next
  // reconstruct. The report is, to find out why.
  for (int k = 0; k < result.rig.num_cameras(); ++k) {
    try {
      CheckLensIsPlausible(result.rig.camera(k), "");
    } catch (const InputError& e) {
      WriteFileAtomically(report_path, result.report.ToJson());
      throw InputError(rig_path, "not written: the calibration gave camera " + std::to_string(k) +
                                     " a lens no camera has (" + e.problem() +
                                     "); its captures do not constrain it (more views, reaching the imager's "
                                     "corners); the report is in " +
                                     report_path);
    }
  }
  AtomicOutputSet outputs;
  outputs.Add(rig_path, RigToYaml(result.rig));
  outputs.Add(report_path, result.report.ToJson());
  if (!cameramodels_dir.empty()) AddCameramodels(result.rig, cameramodels_dir, &outputs);
  outputs.Commit();
}

}  // namespace stereorig
