// The target study: which board, and how many captures, the default rig's
// calibration needs. For each board and capture count it Monte Carlo-
// calibrates the default rig on corner-level synthetic captures: the
// simulator's own target poses (datasets/calibration_poses.h), the true
// corners of the physical board (with the simulator's scale-error and
// misalignment knobs) projected through the TRUE cameras, plus Gaussian
// corner noise (default 0.031 px, the detection noise measured on the
// simulator's rendered images). It reports, over the seeds, the 95th
// percentile of:
//   - the baseline error of each module (mm);
//   - each module's 3D error in the volume after rigid alignment (mm);
//   - the modules' agreement through S (mm).
// docs/calibration.md records the table and the conclusion.
//
//   target_study [--boards 9x7@10,11x9@9,11x9@10,13x11@8] [--captures 25,50,100]
//                [--seeds 20] [--noise-px 0.031] [--threads 2] [--csv FILE]
//                [--scale-error-ppm 0] [--back-misalignment-deg 0] [--back-misalignment-mm 0]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "calib/calibrate.h"
#include "calib/core/input_error.h"
#include "calib/rig_compare.h"
#include "calib/synthetic.h"
#include "datasets/calibration_poses.h"
#include "datasets/default_rig.h"
#include "datasets/target_render.h"

namespace stereorig {
namespace {

struct Board {
  int corners_x = 0, corners_y = 0;
  double square_size_mm = 0;
  std::string label;  // as given, e.g. "11x9@9"
};

Board ParseBoard(const std::string& s) {
  Board b;
  char x = 0, at = 0;
  std::istringstream in(s);
  if (!(in >> b.corners_x >> x >> b.corners_y >> at >> b.square_size_mm) || x != 'x' || at != '@' || b.corners_x < 2 ||
      b.corners_y < 2 || !(b.square_size_mm > 0)) {
    throw InputError("--boards", "'" + s + "' is not COLSxROWS@SQUARE_MM (inner corners), e.g. 11x9@9");
  }
  b.label = s;
  return b;
}

std::vector<std::string> SplitCommas(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

struct StudyOptions {
  int seeds = 20;                      // Monte Carlo runs per board and count
  double noise_px = 0.031;             // corner noise, 1 sigma per coordinate, px
  double scale_error_ppm = 0;          // the printed board larger than nominal
  double back_misalignment_deg = 0.0;  // back print turned in its plane
  double back_misalignment_mm = 0.0;   // back print shifted in its plane
};

struct RunFigures {
  bool ok = false;
  std::string error;
  std::vector<double> baseline_error_mm;  // (modules,) |calibrated - true|
  std::vector<double> module_3d_mm;       // (modules,)
  double agreement_mm = 0;
  double corners_per_view = 0;
  double seconds = 0;
};

RunFigures RunOne(const Board& b, int captures, unsigned seed, const StudyOptions& so) {
  RunFigures f;
  const auto t0 = std::chrono::steady_clock::now();
  const SimulatedRig sim = MakeDefaultRig();
  const Rig& truth = sim.rig;
  const Target target = DoubleSidedTarget(b.corners_x, b.corners_y, b.square_size_mm);
  CalibrationSpec spec;
  spec.captures = captures;
  spec.scale_error_ppm = so.scale_error_ppm;
  spec.back_misalignment_deg = so.back_misalignment_deg;
  spec.back_misalignment_mm = so.back_misalignment_mm;
  const PhysicalBoard board = MakePhysicalBoard(target, spec);
  std::vector<Pose> world_from_camera;
  for (int c = 0; c < truth.num_cameras(); ++c) {
    world_from_camera.push_back(sim.world_from_module0 * truth.CamFromReference(c).Inverse());
  }
  const Pose ref_from_world = sim.world_from_module0.Inverse();
  std::vector<Pose> ref_from_front;
  for (const Pose& world_from_front : MakeCalibrationPoses(spec, board, truth.cameras(), world_from_camera, seed)) {
    ref_from_front.push_back(ref_from_world * world_from_front);
  }
  SyntheticOptions o;
  o.seed = seed;
  o.noise_px = so.noise_px;
  const SyntheticData data = ObserveBoards(
      truth, TargetGeometryFromTarget(target), ref_from_front,
      [&](Face face, int id) { return board.TrueCornerInFront(face, id); }, o);
  size_t corners = 0;
  for (const BoardObservation& v : data.input.observations) corners += v.corner_ids.size();
  f.corners_per_view = static_cast<double>(corners) / std::max<size_t>(1, data.input.observations.size());

  CalibrationOptions opt;
  opt.system.compute_covariance = false;  // not needed here, and the slowest step
  CalibrationResult r;
  try {
    r = Calibrate(data.input, opt);
  } catch (const std::exception& e) {
    f.error = e.what();
    return f;
  }
  if (!r.report.not_converged.empty()) {  // no rig: calibrate would write none (calib/convergence.h)
    f.error = r.report.not_converged;
    return f;
  }
  const auto points = VolumePoints(ref_from_world, Eigen::Vector3d(75, 75, 50), 500, seed + 1000);
  for (int k = 0; k < truth.num_modules(); ++k) {
    f.baseline_error_mm.push_back(
        std::abs(r.rig.module(k).right_from_left.DistanceMm() - truth.module(k).right_from_left.DistanceMm()));
    std::vector<Eigen::Vector3d> pc, pt;
    TriangulateThroughModule(truth, r.rig, k, points, &pc, &pt);
    f.module_3d_mm.push_back(RigidAlignedRms(pt, pc));
  }
  f.agreement_mm = ModuleAgreementRms(truth, r.rig, r.rig.S(0, 1), 0, 1, points);
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  f.ok = true;
  return f;
}

// Nearest-rank percentile (p in (0, 100]) of `v`; NaN if empty.
double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * v.size()));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

int Main(int argc, char** argv) {
  CLI::App app{
      "Monte Carlo study of the calibration target and capture count on the default rig (corner-level synthetic "
      "captures at the simulator's target poses).\n"
      "Example: target_study --boards 9x7@10,11x9@9 --captures 25,50 --seeds 20 --threads 2 --csv study.csv"};
  std::string boards_arg = "9x7@10,11x9@9,11x9@10,13x11@8", captures_arg = "25,50,100", csv_path;
  int threads = 2;
  StudyOptions so;
  app.add_option("--boards", boards_arg, "comma-separated COLSxROWS@SQUARE_MM (inner corners)")->capture_default_str();
  app.add_option("--captures", captures_arg, "comma-separated capture counts")->capture_default_str();
  app.add_option("--seeds", so.seeds, "Monte Carlo runs per board and count")->capture_default_str();
  app.add_option("--noise-px", so.noise_px, "corner noise, 1 sigma per coordinate, px")->capture_default_str();
  app.add_option("--threads", threads, "parallel calibrations")->capture_default_str();
  app.add_option("--scale-error-ppm", so.scale_error_ppm, "printed board larger than nominal, ppm")
      ->capture_default_str();
  app.add_option("--back-misalignment-deg", so.back_misalignment_deg, "back print turned in its plane, deg")
      ->capture_default_str();
  app.add_option("--back-misalignment-mm", so.back_misalignment_mm, "back print shifted in its plane, mm")
      ->capture_default_str();
  app.add_option("--csv", csv_path, "also write the table as CSV");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    std::vector<Board> boards;
    for (const std::string& s : SplitCommas(boards_arg)) boards.push_back(ParseBoard(s));
    std::vector<int> counts;
    for (const std::string& s : SplitCommas(captures_arg)) {
      counts.push_back(std::atoi(s.c_str()));
      if (counts.back() < 5) throw InputError("--captures", "'" + s + "' must be a count >= 5");
    }
    if (boards.empty() || counts.empty()) throw InputError("--boards/--captures", "nothing to study");
    if (so.seeds < 1) throw InputError("--seeds", "must be >= 1");
    if (threads < 1) throw InputError("--threads", "must be >= 1");
    if (!(so.noise_px >= 0)) throw InputError("--noise-px", "must be >= 0");

    struct Job {
      int board, count;
      unsigned seed;
    };
    std::vector<Job> jobs;
    for (size_t b = 0; b < boards.size(); ++b)
      for (size_t c = 0; c < counts.size(); ++c)
        for (int s = 0; s < so.seeds; ++s) jobs.push_back({static_cast<int>(b), static_cast<int>(c), 1u + s});
    std::vector<RunFigures> results(jobs.size());
    std::atomic<size_t> next{0};
    std::mutex print;
    size_t done = 0;
    const auto t0 = std::chrono::steady_clock::now();
    auto worker = [&]() {
      for (size_t i = next++; i < jobs.size(); i = next++) {
        const Job& j = jobs[i];
        results[i] = RunOne(boards[j.board], counts[j.count], j.seed, so);
        std::lock_guard<std::mutex> lock(print);
        ++done;
        std::fprintf(stderr, "\rtarget_study: %zu/%zu calibrations (%.0f s)", done, jobs.size(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr, "\n");

    std::printf("noise %.3f px, %d seeds, scale error %.0f ppm, back misalignment %.3f deg / %.3f mm\n\n", so.noise_px,
                so.seeds, so.scale_error_ppm, so.back_misalignment_deg, so.back_misalignment_mm);
    std::printf(
        "| board | captures | corners/view | baseline error p95 (mm) | module 3D error p95 (mm) | agreement p95 (mm) | "
        "s/calibration | failed |\n");
    std::printf("| --- | --- | --- | --- | --- | --- | --- | --- |\n");
    std::ofstream csv;
    if (!csv_path.empty()) {
      csv.open(csv_path);
      if (!csv) throw InputError(csv_path, "cannot write");
      csv << "board,captures,corners_per_view,baseline_error_p95_mm,module_3d_p95_mm,agreement_p95_mm,"
             "seconds_per_calibration,failed\n";
    }
    double cpu = 0;
    for (size_t b = 0; b < boards.size(); ++b) {
      for (size_t c = 0; c < counts.size(); ++c) {
        std::vector<double> baseline, e3d, agree;
        double corners = 0, seconds = 0;
        int ok = 0, failed = 0;
        for (size_t i = 0; i < jobs.size(); ++i) {
          if (jobs[i].board != static_cast<int>(b) || jobs[i].count != static_cast<int>(c)) continue;
          const RunFigures& f = results[i];
          if (!f.ok) {
            ++failed;
            std::fprintf(stderr, "%s, %d captures, seed %u: %s\n", boards[b].label.c_str(), counts[c], jobs[i].seed,
                         f.error.c_str());
            continue;
          }
          ++ok;
          baseline.insert(baseline.end(), f.baseline_error_mm.begin(), f.baseline_error_mm.end());
          e3d.insert(e3d.end(), f.module_3d_mm.begin(), f.module_3d_mm.end());
          agree.push_back(f.agreement_mm);
          corners += f.corners_per_view;
          seconds += f.seconds;
        }
        cpu += seconds;
        const double pb = Percentile(baseline, 95), p3 = Percentile(e3d, 95), pa = Percentile(agree, 95);
        const double cpv = ok ? corners / ok : 0, spc = ok ? seconds / ok : 0;
        std::printf("| %s | %d | %.0f | %.4f | %.4f | %.4f | %.2f | %d |\n", boards[b].label.c_str(), counts[c], cpv,
                    pb, p3, pa, spc, failed);
        if (csv) {
          csv << boards[b].label << "," << counts[c] << "," << cpv << "," << pb << "," << p3 << "," << pa << "," << spc
              << "," << failed << "\n";
        }
      }
    }
    std::printf("\n%zu calibrations in %.0f s wall (%d threads), %.0f s of calibration time\n", jobs.size(), wall,
                threads, cpu);
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "target_study: %s\n", e.what());
    return 2;
  }
}

}  // namespace
}  // namespace stereorig

int main(int argc, char** argv) { return stereorig::Main(argc, argv); }
