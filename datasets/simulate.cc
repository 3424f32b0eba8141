#include "datasets/simulate.h"

#include <fcntl.h>  // AT_FDCWD
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc, _GNU_SOURCE)

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <system_error>
#include <thread>

#include "calib/core/capture_image_name.h"
#include "calib/core/float_tiff.h"
#include "calib/core/folder_to_create.h"
#include "calib/core/input_error.h"
#include "calib/core/pending_temporary.h"
#include "calib/core/png_writer.h"
#include "calib/core/rig_file.h"
#include "calib/core/temporary_name.h"
#include "datasets/calibration_poses.h"
#include "datasets/camera_rays.h"
#include "datasets/render.h"
#include "datasets/rng.h"
#include "datasets/scene_objects.h"
#include "datasets/target_render.h"
#include "reconstruct/metrology/artifact.h"
#include "targets/target_file.h"

namespace stereorig {

namespace fs = std::filesystem;

namespace {

// Stream kinds: every random draw of the dataset comes from StreamKey({seed, kind, ...}).
enum : uint64_t {
  kKeyPoses = 1,
  kKeyStray = 2,
  kKeyCalibSensor = 3,
  kKeyScene = 4,
  kKeyPassiveSensor = 5,
  kKeyActiveSensor = 6,
  kKeySpeckle = 7,
  kKeyBump = 8,
};

std::string Matrix4Yaml(const Pose& p, const std::string& indent) {
  const Eigen::Matrix4d m = p.ToMatrix4();
  std::string s;
  for (int r = 0; r < 4; ++r) {
    s += indent + "- [";
    for (int c = 0; c < 4; ++c) s += (c ? ", " : "") + FormatDouble(m(r, c));
    s += "]\n";
  }
  return s;
}

std::string Vec3Yaml(const Eigen::Vector3d& v) {
  std::ostringstream o;
  o << '[' << FormatDouble(v.x()) << ", " << FormatDouble(v.y()) << ", " << FormatDouble(v.z()) << ']';
  return o.str();
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw InputError(path.string(), "cannot write");
}

// An 8-bit grey PNG (captures, id and lit maps; deflate level 1: fast, as
// the dataset's writer always was) or the float32 TIFF of a depth map.
void WriteImage(const fs::path& path, const cv::Mat& image) {
  if (path.extension() == ".tiff") {
    STEREORIG_CHECK(image.type() == CV_32FC1);
    WriteFloatTiff(path.string(), image.cols, image.rows, image.ptr<float>(), image.step);
    return;
  }
  STEREORIG_CHECK(path.extension() == ".png" && image.type() == CV_8UC1);
  WriteText(path, EncodePng({uint32_t(image.cols), uint32_t(image.rows), 1, 8, image.data, image.step}, 1));
}

void WritePly(const fs::path& path, const std::vector<Eigen::Vector3d>& points) {
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat binary_little_endian 1.0\ncomment stereorig simulator: true surface, reference frame "
       "(module 0), mm\nelement vertex "
    << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  std::vector<float> buf(3 * points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    for (int a = 0; a < 3; ++a) buf[3 * i + a] = static_cast<float>(points[i][a]);
  }
  f.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size() * sizeof(float)));
  if (!f) throw InputError(path.string(), "cannot write");
}

// Runs f(0..n-1) on up to `threads` threads, never more than n (a thread
// with no job is only a cost); rethrows the first exception. A thread the
// system refuses to start leaves the work to those already running (to
// this one, if none started).
void ParallelFor(int n, int threads, const std::function<void(int)>& f) {
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      try {
        f(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::min(std::max(1, threads), n); ++t) {
    try {
      pool.emplace_back(worker);
    } catch (const std::system_error&) {
      break;
    }
  }
  if (pool.empty()) worker();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// Whether the simulator writes `relative` (a path inside a dataset, as
// simulate.h's layout gives it) as a folder (`folder`) or as a file.
bool SimulatorWrites(const fs::path& relative, bool folder) {
  std::vector<std::string> p;
  for (const fs::path& part : relative) p.push_back(part.string());
  const std::vector<std::string> scene_names = ScenesSpec().names;  // every scene there is
  const auto scene = [&](const std::string& name) {
    return std::find(scene_names.begin(), scene_names.end(), name) != scene_names.end();
  };
  const auto camera_png = [](const std::string& name, const std::string& prefix) {
    return name.starts_with(prefix) && CameraIndexOfImageName(name.substr(prefix.size())).has_value();
  };
  const auto one_of = [](const std::string& name, std::initializer_list<const char*> names) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  const size_t n = p.size();
  if (n == 1)
    return folder ? one_of(p[0], {"artifacts", "calibration", "scenes", "truth"})
                  : one_of(p[0], {"spec.yaml", "target.yaml", "layout.yaml"});
  if (p[0] == "artifacts") return n == 2 && !folder && one_of(p[1], {"sphere.yaml", "ballbar.yaml", "plate.yaml"});
  if (p[0] == "calibration") {
    const bool capture = p[1].size() == 3 && std::all_of(p[1].begin(), p[1].end(), ::isdigit);
    return capture && (n == 2 ? folder : n == 3 && !folder && camera_png(p[2], ""));
  }
  if (p[0] == "scenes") {
    if (!scene(p[1])) return false;
    if (n == 2) return folder;
    if (!one_of(p[2], {"active", "passive"})) return false;
    return n == 3 ? folder : n == 4 && !folder && camera_png(p[3], "");
  }
  STEREORIG_CHECK(p[0] == "truth");  // n >= 2 below a top-level name of the first test
  if (n == 2)
    return folder ? p[1] == "scenes" : one_of(p[1], {"rig.yaml", "calibration_poses.yaml", "simulation.yaml"});
  if (p[1] != "scenes" || !scene(p[2])) return false;
  if (n == 3) return folder;
  return n == 4 && !folder &&
         (one_of(p[3], {"object.yaml", "surface.ply"}) || camera_png(p[3], "id_") || camera_png(p[3], "lit_") ||
          (p[3].starts_with("depth_") && p[3].ends_with(".tiff") &&
           camera_png(p[3].substr(0, p[3].size() - 5) + ".png", "depth_")));
}

// Throws InputError naming `typed` if `out` is one of `inputs`, or holds one:
// replacing the folder would delete it.
void RequireNoInputIn(const std::string& typed, const fs::path& out,
                      const std::vector<std::pair<std::string, std::string>>& inputs) {
  const fs::path folder = NormalPath(out);
  for (const auto& [path, what] : inputs) {
    if (path.empty()) continue;
    const fs::path input = NormalPath(path);
    const auto [end, unused] = std::mismatch(folder.begin(), folder.end(), input.begin(), input.end());
    if (end != folder.end()) continue;  // not below `folder`
    throw InputError(typed, input == folder ? "is " + what + ", not a folder for the dataset (--out)"
                                            : "holds " + what + " " + path +
                                                  ": replacing the folder with the dataset would delete it");
  }
}

// The true rig from its cameras and each one's world pose (module frame =
// left camera).
Rig RigFromWorldPoses(const Rig& like, const std::vector<Camera>& cameras, const std::vector<Pose>& world_from_camera) {
  std::vector<StereoModule> modules = like.modules();
  std::vector<Pose> module0_from_module;
  const Pose& world_from_module0 = world_from_camera[like.module(0).left_camera];
  for (StereoModule& m : modules) {
    m.right_from_left = world_from_camera[m.right_camera].Inverse() * world_from_camera[m.left_camera];
    module0_from_module.push_back(world_from_module0.Inverse() * world_from_camera[m.left_camera]);
  }
  Rig rig(cameras, like.camera_names(), modules, module0_from_module);
  rig.provenance() = like.provenance();
  return rig;
}

// A random unit vector from the bump stream.
Eigen::Vector3d RandomAxis(Rng* rng) {
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(rng->Uniform(-1, 1), rng->Uniform(-1, 1), rng->Uniform(-1, 1));
  } while (v.norm() > 1 || v.norm() < 0.1);
  return v.normalized();
}

std::string Num3(int i) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%03d", i);
  return buf;
}

class Progress {
 public:
  Progress(const std::function<void(const std::string&)>& sink, int total) : sink_(sink), total_(total) {}
  void Done(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    const int pct = total_ ? 100 * done_ / total_ : 100;
    if (sink_ && (pct / 5 != last_ / 5 || done_ == total_)) {
      last_ = pct;
      sink_("[" + std::to_string(pct) + "%] " + std::to_string(done_) + "/" + std::to_string(total_) + " jobs (" +
            what + ")");
    }
  }

 private:
  std::function<void(const std::string&)> sink_;
  int total_, done_ = 0, last_ = -1;
  std::mutex mutex_;
};

// A spec can place a camera where the board never reaches (a module
// looking away): MakeCalibrationPoses keeps its best draw, and the dataset
// then holds captures no calibration can use for that camera. Said on the
// progress sink, "warning: ...", for each camera that sees fewer than
// min_corners_per_camera corners in every capture (truth/
// calibration_poses.yaml gives the count per capture). Not a refusal: a ring
// of 3 modules at 120° keeps some captures below the minimum by design.
void WarnOfCamerasTheBoardMisses(const CalibrationSpec& calibration, const PhysicalBoard& board, const Rig& rig,
                                 const std::vector<Pose>& world_from_camera, const std::vector<Pose>& poses,
                                 const std::function<void(const std::string&)>& say) {
  if (poses.empty()) return;
  for (const StereoModule& m : rig.modules()) {
    for (const int cam : {m.left_camera, m.right_camera}) {
      int most = 0;
      for (const Pose& world_from_front : poses)
        most = std::max(most, CornersInView(rig.camera(cam), world_from_camera[cam], world_from_front, board));
      if (most >= calibration.min_corners_per_camera) continue;
      say("warning: cam" + std::to_string(cam) + " (" + m.name + "'s " + (cam == m.left_camera ? "left" : "right") +
          " camera) sees at most " + std::to_string(most) + " target corners in any of the " +
          std::to_string(poses.size()) + " calibration captures, fewer than calibration.min_corners_per_camera (" +
          std::to_string(calibration.min_corners_per_camera) + "): check the module's center_mm and look_at_mm");
    }
  }
}

// Likewise a projector that lights no pixel of any camera in any scene (one
// past the volume, or turned away): the active images are its module's
// passive ones. Said for each enabled projector (the `lit` bits, in module
// order) whose count is 0.
void WarnOfProjectorsLightingNothing(const SimSpec& spec, const std::vector<std::atomic<int64_t>>& lit_px,
                                     const std::function<void(const std::string&)>& say) {
  size_t k = 0;
  for (size_t m = 0; m < spec.modules.size(); ++m) {
    const ProjectorSpec& p = spec.modules[m].projector;
    if (!p.enabled || p.power_dn <= 0) continue;  // as MakeProjectors
    if (lit_px[k++] == 0)
      say("warning: modules[" + std::to_string(m) + "] (" + spec.modules[m].name +
          ")'s projector lights no pixel of any camera in any scene: check its offset_mm and the module's look_at_mm");
  }
}

}  // namespace

void CheckReplaceableOut(const std::string& typed, const fs::path& out) {
  if (!fs::exists(out)) return;
  if (!fs::is_directory(out)) throw InputError(typed, "exists and is not a folder");
  if (fs::is_empty(out)) return;
  if (!fs::exists(out / "spec.yaml"))
    throw InputError(typed, "exists and is not a stereorig dataset (no spec.yaml); refusing to replace it");
  // A spec.yaml alone is a project folder as often as a dataset (a user's
  // own spec, next to their board and notes): the simulator's info file
  // tells an earlier dataset apart.
  std::ifstream info(out / "truth" / "simulation.yaml");
  std::string line;
  bool ours = false;
  while (!ours && std::getline(info, line)) ours = line == "format: stereorig-sim-info";
  if (!ours)
    throw InputError(typed,
                     "exists and is not a stereorig dataset (no truth/simulation.yaml of format stereorig-sim-info); "
                     "refusing to replace it");
  // The folder is replaced whole: anything kept in it that the simulator
  // does not write (notes, scores, a calibrated rig) would go with it.
  std::vector<fs::path> foreign;
  for (auto it = fs::recursive_directory_iterator(out); it != fs::recursive_directory_iterator(); ++it) {
    const fs::file_status status = it->symlink_status();
    const bool folder = fs::is_directory(status);
    if ((folder || fs::is_regular_file(status)) && SimulatorWrites(it->path().lexically_relative(out), folder))
      continue;
    foreign.push_back(it->path().lexically_relative(out));
    if (folder) it.disable_recursion_pending();
  }
  if (!foreign.empty())
    throw InputError(typed, "holds " + std::min_element(foreign.begin(), foreign.end())->string() +
                                ", which the simulator does not write; refusing to replace the dataset and delete it "
                                "(move it out, or choose another --out)");
}

void SimulateOptions::Check() const {
  if (out_dir.empty()) throw InputError("--out", "an output folder is required");
  if (threads < 0 || threads > kMaxSimulateThreads)
    throw InputError("--threads", "must be in [0, " + std::to_string(kMaxSimulateThreads) + "] (0 = every core)");
  if (calibration_captures < -1 || calibration_captures > 999) {
    throw InputError("--calibration-captures", "must be in [0, 999]");
  }
  if (!(surface_spacing_mm > 0 && surface_spacing_mm <= 0.2)) {
    throw InputError("surface_spacing_mm", "must be in (0, 0.2]");
  }
  // -1 is "none"; below it, Any() would drop the bump without a word. The
  // upper bounds need the rig: Simulate checks them.
  if (bump.camera < -1) throw InputError("--bump-camera", "no camera " + std::to_string(bump.camera));
  if (bump.module < -1) throw InputError("--bump-module", "no module " + std::to_string(bump.module));
  if (bump.camera >= 0 && bump.module >= 0) throw InputError("--bump-camera", "bump a camera or a module, not both");
  // Written so that NaN fails too: it used to reach the rig's own check,
  // which named neither the flag nor the bump.
  if (!(std::abs(bump.rotation_deg) <= 10)) throw InputError("--bump-rotation-deg", "must be within +-10");
  if (!(std::abs(bump.translation_mm) <= 10)) throw InputError("--bump-translation-mm", "must be within +-10");
  // A lens belongs to one camera; a whole module's lenses do not drift as one.
  if (bump.lens.Any() && bump.camera < 0) {
    throw InputError(bump.lens.focal_percent != 0 ? "--bump-focal-percent" : "--bump-principal-point-px",
                     "needs --bump-camera (a lens drifts in one camera, not in a whole module)");
  }
  // Written so that NaN fails too. 10 % is a focal length no focus ring
  // turns by unnoticed; 50 px is 7 % of the default sensor's width.
  if (!(std::abs(bump.lens.focal_percent) <= 10)) throw InputError("--bump-focal-percent", "must be within +-10");
  if (!(std::abs(bump.lens.principal_point_px.x()) <= 50 && std::abs(bump.lens.principal_point_px.y()) <= 50))
    throw InputError("--bump-principal-point-px", "each of DX and DY must be within +-50 px");
}

SimulateSummary Simulate(const SimSpec& spec_in, const SimulateOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  options.Check();
  SimSpec spec = spec_in;
  if (options.calibration_captures >= 0) spec.calibration.captures = options.calibration_captures;
  if (!options.scenes) spec.scenes.names.clear();
  spec.Check();
  const int threads = options.threads > 0
                          ? options.threads
                          : std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxSimulateThreads);
  auto say = [&](const std::string& s) {
    if (options.progress) options.progress(s);
  };
  const uint64_t seed = options.seed;

  // --- the true rig, bumped if asked
  SpecRig sr = BuildSpecRig(spec);
  const int num_cameras = sr.sim.rig.num_cameras();
  std::string bump_yaml = "bump: none\n";
  if (options.bump.Any()) {
    const RigBump& b = options.bump;
    Rng rng(StreamKey({seed, kKeyBump}));
    const Eigen::Vector3d axis = RandomAxis(&rng), dir = RandomAxis(&rng);
    const Pose delta(Eigen::AngleAxisd(b.rotation_deg * M_PI / 180.0, axis).toRotationMatrix(),
                     b.translation_mm * dir);  // in the moved camera's / module's own frame
    std::vector<Camera> cameras = sr.sim.rig.cameras();
    if (b.camera >= 0) {
      if (b.camera >= num_cameras) throw InputError("--bump-camera", "no camera " + std::to_string(b.camera));
      sr.world_from_camera[b.camera] = sr.world_from_camera[b.camera] * delta;
      // The drifted lens renders the images and is what truth/rig.yaml
      // records: the truth is the rig as it now is.
      cameras[b.camera] = WithLensDrift(cameras[b.camera], b.lens);
    } else {
      if (b.module >= sr.sim.rig.num_modules())
        throw InputError("--bump-module", "no module " + std::to_string(b.module));
      const StereoModule& m = sr.sim.rig.module(b.module);
      const Pose world_from_module = sr.world_from_camera[m.left_camera];
      const Pose moved = world_from_module * delta * world_from_module.Inverse();  // world_from_world'
      sr.world_from_camera[m.left_camera] = moved * sr.world_from_camera[m.left_camera];
      sr.world_from_camera[m.right_camera] = moved * sr.world_from_camera[m.right_camera];
      sr.world_from_projector[b.module] = moved * sr.world_from_projector[b.module];
    }
    sr.sim.rig = RigFromWorldPoses(sr.sim.rig, cameras, sr.world_from_camera);
    sr.sim.world_from_module0 = sr.world_from_camera[sr.sim.rig.module(0).left_camera];
    std::ostringstream o;
    o << "bump:\n"
      << "  camera: " << b.camera << "\n  module: " << b.module << "\n"
      << "  rotation_deg: " << FormatDouble(b.rotation_deg) << "\n  rotation_axis: " << Vec3Yaml(axis) << "\n"
      << "  translation_mm: " << FormatDouble(b.translation_mm) << "\n  translation_direction: " << Vec3Yaml(dir)
      << "\n  frame: \"the moved camera's (or the module's left camera's) own frame, before the move\"\n"
      << "  focal_percent: " << FormatDouble(b.lens.focal_percent) << "\n  principal_point_px: ["
      << FormatDouble(b.lens.principal_point_px.x()) << ", " << FormatDouble(b.lens.principal_point_px.y()) << "]\n";
    bump_yaml = o.str();
  }
  const Rig& rig = sr.sim.rig;
  const Pose module0_from_world = sr.sim.world_from_module0.Inverse();
  sr.sim.rig.provenance().input = "stereorig simulate, seed " + std::to_string(seed);

  const Target target =
      spec.calibration.target == "default" ? DefaultTarget() : ReadTargetFile(spec.calibration.target);
  const PhysicalBoard board = MakePhysicalBoard(target, spec.calibration);
  const std::vector<LaserProjector> projectors =
      MakeProjectors(spec, sr.world_from_projector, sr.projector_distance_mm);

  // --- the output folder: a sibling temporary, renamed at the end
  // The work is done on `out`, absolute and normalised; messages name the
  // folder as the user typed it (they used to name `out`).
  const std::string& typed = options.out_dir;
  fs::path out = fs::absolute(fs::path(typed)).lexically_normal();
  // "ds/" (or ".") normalises to a path ending in a separator, whose parent
  // is the folder itself: renaming it into place would then fail.
  if (!out.has_filename()) out = out.parent_path();
  const fs::path parent = out.parent_path();
  // Every name to create fits the file system, the dataset's own included,
  // as every command's output folders are checked (apps/output_paths.h): a
  // name too long used to surface as a raw std::filesystem error, or as a
  // rename failing after all the rendering.
  std::vector<fs::path> missing;
  CheckNamesFit(typed, "create this folder for the dataset (--out)", DeepestExistingPart(NormalPath(out), &missing),
                missing);
  // Before any folder is made: an input inside `out`, or a folder that is
  // not an earlier dataset, is refused with nothing created.
  std::vector<std::pair<std::string, std::string>> inputs = options.inputs;
  if (spec.calibration.target != "default")
    inputs.push_back({spec.calibration.target, "the spec's target file (calibration.target)"});
  RequireNoInputIn(typed, out, inputs);
  CheckReplaceableOut(typed, out);
  // Made now, and removed again while empty if the run fails after this (a
  // folder that cannot be made, part way too): no new empty folder left.
  FolderToCreate parent_folder(parent.string(), "the dataset (--out)");
  try {
    parent_folder.Create();
  } catch (const InputError& e) {  // named by the folder above it: named as typed
    throw InputError(typed, e.problem());
  }
  std::error_code ec;
  const std::string pid = std::to_string(getpid());
  const fs::path tmp = parent / TemporaryName(".", out.filename().string(), ".tmp-" + pid);
  fs::remove_all(tmp, ec);
  // Removed if the run fails, by an exception or a termination signal.
  struct Cleanup {
    fs::path path;
    PendingTemporary pending{path.string(), TemporaryKind::kFolder};
    bool keep = false;
    ~Cleanup() {
      std::error_code e;
      if (!keep) fs::remove_all(path, e);
    }
  } cleanup{tmp};
  fs::create_directories(tmp / "truth", ec);
  if (ec)
    throw InputError(typed, "cannot create its temporary folder " + tmp.filename().string() + ": " + ec.message());

  // --- ray tables
  const auto t_rays = std::chrono::steady_clock::now();
  say("unprojecting the ray tables of " + std::to_string(num_cameras) + " cameras");
  std::vector<std::unique_ptr<CameraRays>> rays;
  const bool render_anything = spec.calibration.captures > 0 || !spec.scenes.names.empty();
  for (int i = 0; i < num_cameras && render_anything; ++i) {
    rays.push_back(std::make_unique<CameraRays>(rig.camera(i), threads));
  }
  const double rays_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_rays).count();
  std::vector<cv::Mat> stray;
  for (int i = 0; i < num_cameras; ++i) {
    stray.push_back(StrayLight(rig.camera(i).imager_width_px(), rig.camera(i).imager_height_px(), spec.render,
                               StreamKey({seed, kKeyStray, static_cast<uint64_t>(i)})));
  }

  // --- calibration poses and scenes
  const int captures = spec.calibration.captures;
  const std::vector<Pose> poses =
      MakeCalibrationPoses(spec.calibration, board, rig.cameras(), sr.world_from_camera, StreamKey({seed, kKeyPoses}));
  WarnOfCamerasTheBoardMisses(spec.calibration, board, rig, sr.world_from_camera, poses, say);
  std::vector<Scene> scenes;
  for (size_t s = 0; s < spec.scenes.names.size(); ++s) {
    scenes.push_back(MakeScene(spec.scenes.names[s], spec.scenes, spec.render,
                               StreamKey({seed, kKeyScene, static_cast<uint64_t>(s)})));
  }
  for (int k = 0; k < captures; ++k) fs::create_directories(tmp / "calibration" / Num3(k));
  for (const Scene& s : scenes) {
    fs::create_directories(tmp / "scenes" / s.name / "active");
    fs::create_directories(tmp / "scenes" / s.name / "passive");
    fs::create_directories(tmp / "truth" / "scenes" / s.name);
  }

  // --- render: one job per (scene, camera), one per scene's surface truth,
  // one per (capture, camera). Scenes first: they are the slowest.
  const int num_scene_jobs = static_cast<int>(scenes.size()) * (num_cameras + 1);
  const int num_jobs = num_scene_jobs + captures * num_cameras;
  say("rendering " + std::to_string(captures) + " calibration captures and " + std::to_string(scenes.size()) +
      " scenes x " + std::to_string(num_cameras) + " cameras on " + std::to_string(threads) + " threads");
  Progress progress(options.progress, num_jobs);
  std::vector<std::atomic<int64_t>> lit_px(
      projectors.size());  // per projector: pixels it lights, every scene and camera
  std::atomic<int> images{0};
  ParallelFor(num_jobs, threads, [&](int job) {
    if (job < num_scene_jobs) {
      const int s = job / (num_cameras + 1), cam = job % (num_cameras + 1) - 1;
      const Scene& scene = scenes[s];
      const fs::path truth = tmp / "truth" / "scenes" / scene.name;
      if (cam < 0) {
        std::vector<Eigen::Vector3d> pts = SampleSceneSurface(scene, options.surface_spacing_mm);
        for (Eigen::Vector3d& p : pts) p = module0_from_world * p;
        WritePly(truth / "surface.ply", pts);
        progress.Done(scene.name + " surface");
        return;
      }
      const std::string name = "cam" + std::to_string(cam);
      const SceneRadiance rad = RenderScene(*rays[cam], sr.world_from_camera[cam], scene, projectors, spec.render);
      const uint64_t c = static_cast<uint64_t>(cam), si = static_cast<uint64_t>(s);
      const cv::Mat passive =
          SensorImage(rad.passive, stray[cam], spec.render, StreamKey({seed, kKeyPassiveSensor, si, c}));
      const cv::Mat speckle =
          SpeckleField(rad.laser.cols, rad.laser.rows, spec.render, StreamKey({seed, kKeySpeckle, si, c}));
      const cv::Mat active_radiance = rad.passive + rad.laser.mul(speckle);
      const cv::Mat active =
          SensorImage(active_radiance, stray[cam], spec.render, StreamKey({seed, kKeyActiveSensor, si, c}));
      WriteImage(tmp / "scenes" / scene.name / "passive" / (name + ".png"), passive);
      WriteImage(tmp / "scenes" / scene.name / "active" / (name + ".png"), active);
      WriteImage(truth / ("depth_" + name + ".tiff"), rad.depth);
      WriteImage(truth / ("id_" + name + ".png"), rad.id);
      WriteImage(truth / ("lit_" + name + ".png"), rad.lit);
      for (size_t k = 0; k < projectors.size(); ++k) lit_px[k] += cv::countNonZero(rad.lit & (1 << k));
      images += 2;
      progress.Done(scene.name + " " + name);
      return;
    }
    const int k = (job - num_scene_jobs) / num_cameras, cam = (job - num_scene_jobs) % num_cameras;
    const cv::Mat radiance = RenderTargetRadiance(*rays[cam], sr.world_from_camera[cam], poses[k], board, spec.render);
    const cv::Mat image =
        SensorImage(radiance, stray[cam], spec.render,
                    StreamKey({seed, kKeyCalibSensor, static_cast<uint64_t>(k), static_cast<uint64_t>(cam)}));
    WriteImage(tmp / "calibration" / Num3(k) / ("cam" + std::to_string(cam) + ".png"), image);
    ++images;
    progress.Done("calibration " + Num3(k));
  });

  if (!scenes.empty()) WarnOfProjectorsLightingNothing(spec, lit_px, say);

  // --- the small files
  // The dataset renders again from its own spec: a target file is named as
  // the copy written beside it (a relative target is read from the spec's
  // folder), not as the path it was read from, which may not travel with it.
  SimSpec written = spec;
  if (written.calibration.target != "default") written.calibration.target = "target.yaml";
  WriteText(tmp / "spec.yaml", SimSpecToYaml(written));
  WriteTargetFile(target, (tmp / "target.yaml").string());
  {
    std::ostringstream o;
    o << "# stereorig layout: which cameras form each stereo module (global camera indices).\nmodules:\n";
    for (const StereoModule& m : rig.modules()) {
      o << "  - {name: " << m.name << ", left: " << m.left_camera << ", right: " << m.right_camera << "}\n";
    }
    WriteText(tmp / "layout.yaml", o.str());
  }
  WriteRigFile(sr.sim.rig, (tmp / "truth" / "rig.yaml").string());
  {
    std::ostringstream o;
    o << "# True target poses of the calibration captures. Frame: module 0 (truth/rig.yaml), mm.\n"
      << "format: stereorig-sim-calibration-poses\nversion: 1\n"
      << "board:\n"
      << "  scale: " << FormatDouble(board.scale) << "   # printed / nominal, about each face's first inner corner\n"
      << "  bow_mm: " << FormatDouble(board.bow_mm) << "   # front face bulges towards its viewer at the centre\n"
      << "  true_back_from_front:\n"
      << Matrix4Yaml(board.true_back_from_front, "    ") << "captures:\n";
    for (int k = 0; k < captures; ++k) {
      o << "  - index: " << k << "\n    folder: calibration/" << Num3(k) << "\n    module0_from_front:\n"
        << Matrix4Yaml(module0_from_world * poses[k], "      ") << "    cameras:\n";
      for (int cam = 0; cam < num_cameras; ++cam) {
        const Face face = target.double_sided() ? FaceSeen(sr.world_from_camera[cam], poses[k]) : Face::kFront;
        o << "      - {camera: " << cam << ", face: " << FaceName(face)
          << ", corners_in_view: " << CornersInView(rig.camera(cam), sr.world_from_camera[cam], poses[k], board)
          << "}\n";
      }
    }
    WriteText(tmp / "truth" / "calibration_poses.yaml", o.str());
  }
  for (const Scene& scene : scenes) {
    std::ostringstream o;
    o << "# Analytic truth of scene '" << scene.name << "'. Frame: module 0 (truth/rig.yaml), mm.\n"
      << "format: stereorig-sim-object\nversion: 1\nscene: " << scene.name << "\nobjects:\n";
    for (const SceneObject& obj : scene.objects) {
      const Pose module0_from_object = module0_from_world * obj.world_from_object;
      o << "  - id: " << obj.id << "\n    type: " << obj.type << "\n    description: \"" << obj.description
        << "\"\n    albedo: " << FormatDouble(obj.albedo) << "\n    module0_from_object:\n"
        << Matrix4Yaml(module0_from_object, "      ");
      if (obj.type == "sphere") o << "    center_mm: " << Vec3Yaml(module0_from_object.translation_mm()) << "\n";
      o << "    parameters:\n";
      std::istringstream lines(obj.parameters_yaml);
      for (std::string line; std::getline(lines, line);) o << "      " << line << "\n";
    }
    WriteText(tmp / "truth" / "scenes" / scene.name / "object.yaml", o.str());
  }
  // Certificates of the reference artifacts, as a calibration lab would
  // deliver them (the simulator's true dimensions, certified uncertainty 0),
  // for `stereorig verify --artifact DIR/artifacts/<scene>.yaml`.
  for (const Scene& scene : scenes) {
    Artifact a;
    a.name = scene.name + " (simulated, seed " + std::to_string(seed) + ")";
    if (scene.name == "sphere") {
      a.type = ArtifactType::kSphere;
      a.sphere_diameter_mm = spec.scenes.sphere_diameter_mm;
    } else if (scene.name == "ballbar") {
      a.type = ArtifactType::kBallBar;
      a.sphere_diameter_mm = spec.scenes.ballbar_sphere_diameter_mm;
      a.center_distance_mm = spec.scenes.ballbar_distance_mm;
    } else if (scene.name == "plate") {
      a.type = ArtifactType::kPlate;
      a.plate_length_mm = spec.scenes.plate_size_mm.x();
      a.plate_width_mm = spec.scenes.plate_size_mm.y();
    } else {
      continue;
    }
    fs::create_directories(tmp / "artifacts");
    WriteText(tmp / "artifacts" / (scene.name + ".yaml"), ArtifactToYaml(a));
  }
  {
    std::ostringstream o;
    o << "# How this dataset was made (what is not in spec.yaml).\nformat: stereorig-sim-info\nversion: 1\n"
      << "tool: \"" << ToolVersion() << "\"\nseed: " << seed << "\ncalibration_captures: " << captures << "\nscenes: [";
    for (size_t s = 0; s < scenes.size(); ++s) o << (s ? ", " : "") << scenes[s].name;
    o << "]\nsurface_spacing_mm: " << FormatDouble(options.surface_spacing_mm) << "\n"
      << "depth_maps: \"float32 TIFF, z in the camera frame (mm) at the pixel centre, 0 = no surface\"\n"
      << "world_from_module0:\n"
      << Matrix4Yaml(sr.sim.world_from_module0, "  ") << bump_yaml;
    WriteText(tmp / "truth" / "simulation.yaml", o.str());
  }

  // --- into place
  // An earlier dataset is swapped with the new one in one step where the
  // file system can (renameat2's RENAME_EXCHANGE): `out` is then a whole
  // dataset at every instant, and the temporary folder, which a termination
  // signal removes, holds the new one before the swap and the old one after
  // it. (With two renames, a signal between them removed the new dataset
  // and left the old one hidden: nothing at `out`.)
  if (fs::exists(out) && renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, out.c_str(), RENAME_EXCHANGE) == 0) {
    fs::remove_all(tmp, ec);     // the earlier dataset; `cleanup` still covers it
  } else if (fs::exists(out)) {  // no exchange here (e.g. an older kernel): two renames
    const fs::path old = parent / TemporaryName(".", out.filename().string(), ".old-" + pid);
    fs::rename(out, old, ec);
    if (ec) throw InputError(typed, "cannot replace: " + ec.message());
    fs::rename(tmp, out, ec);
    if (ec) {
      std::error_code e2;
      fs::rename(old, out, e2);
      throw InputError(typed, "cannot rename the finished dataset into place: " + ec.message());
    }
    const PendingTemporary pending_old(old.string(), TemporaryKind::kFolder);  // a signal finishes the removal
    fs::remove_all(old, ec);
  } else {
    fs::rename(tmp, out, ec);
    if (ec) throw InputError(typed, "cannot rename the finished dataset into place: " + ec.message());
  }
  cleanup.keep = true;

  SimulateSummary summary;
  summary.images = images;
  summary.rays_seconds = rays_seconds;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return summary;
}

}  // namespace stereorig
