// `stereorig bench`: throughput and accuracy of the runtime, side by side with
// the same pipeline whose correspondence step is OpenCV StereoSGBM
// (MODE_SGBM_3WAY), in one run on the same captures.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "apps/reconstruct_json.h"
#include "apps/truth_rig_warning.h"
#include "apps/volume_warning.h"
#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "calib/json_text.h"
#include "datasets/default_rig.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/metrology/ply_points.h"
#include "reconstruct/runtime.h"
#include "reconstruct/scene_score.h"
#include "reconstruct/score.h"
#include "reconstruct/synthetic_scene.h"

namespace stereorig {
namespace {

using Clock = std::chrono::steady_clock;

struct Scene {
  std::string name;
  std::vector<cv::Mat> images;
  std::vector<Eigen::Vector3d> truth;
  // A dataset scene's truth maps (grid-lit, depth, ids): the truth fill, as
  // `stereorig score` measures it. Absent for the built-in scene.
  std::optional<SceneTruth> truth_maps;
  // What of its truth a dataset scene lacks, said on its line (a line's own
  // captures have none): its accuracy or truth fill used to be left out
  // without a word. Empty: it lacks nothing (or is the built-in scene).
  std::string truth_missing{};
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The whole process's (every thread's) CPU time, s, and minor page faults
// so far (each a page the kernel zeroes and maps; on a VM often backed by
// the host at that moment: far steadier than time on a shared machine).
// Only one pipeline runs at a time, so differences across a call are that
// call's.
struct Usage {
  double cpu_s = 0;
  long minor_faults = 0;
};
Usage UsageNow() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return {u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec), u.ru_minflt};
}

double PeakMemoryMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // Linux: KiB
}

// Resident memory now, MB (Linux /proc/self/statm: pages); 0 if unreadable.
double ResidentMemoryMb() {
  long size = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &size, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

struct Pipeline {
  MatcherKind matcher;
  std::unique_ptr<Runtime> runtime;
  double build_ms = 0;
  double busy_s = 0;     // summed wall time of its Process() calls
  double cpu_s = 0;      // summed CPU time (all threads) of its Process() calls
  long page_faults = 0;  // summed minor page faults of its Process() calls
  int objects = 0;
  std::map<std::string, std::vector<double>> steps;
};

// Both pipelines run interleaved (ours, baseline, ours, ...), capture by
// capture, so a change in the machine's load hits both alike; objects/s is
// objects over the summed wall time of each pipeline's own Process() calls.
// Progress on stderr after each run over the scenes (the five default
// scenes take ~20 s a run), outside the timed calls.
void BenchInterleaved(std::vector<Pipeline>& pipelines, const std::vector<Scene>& scenes, int runs) {
  // pipelines[0]: ours, [1]: the SGBM pipeline (the progress line names both).
  STEREORIG_CHECK(pipelines.size() >= 2);
  for (Pipeline& p : pipelines) p.runtime->Process(scenes[0].images, false);  // warm-up
  for (int r = 0; r < runs; ++r) {
    for (const Scene& s : scenes)
      for (Pipeline& p : pipelines) {
        const auto t0 = Clock::now();
        const Usage u0 = UsageNow();
        const Reconstruction rec = p.runtime->Process(s.images, false);
        p.busy_s += std::chrono::duration<double>(Clock::now() - t0).count();
        const Usage u1 = UsageNow();
        p.cpu_s += u1.cpu_s - u0.cpu_s;
        p.page_faults += u1.minor_faults - u0.minor_faults;
        ++p.objects;
        for (const auto& [k, v] : rec.times_ms) p.steps[k].push_back(v);
        for (const ModuleReport& m : rec.modules)
          for (const auto& [k, v] : m.times_ms) p.steps["module" + std::to_string(m.module) + "." + k].push_back(v);
      }
    std::fprintf(stderr, "bench: [%d/%d] run %d timed; so far ours %.1f objects/s, the SGBM pipeline %.1f\n", r + 1,
                 runs, r + 1, pipelines[0].objects / pipelines[0].busy_s, pipelines[1].objects / pipelines[1].busy_s);
  }
  std::fprintf(stderr, "bench: meshing, hole filling and scoring each pipeline's clouds (untimed)...\n");
}

// One pipeline's JSON section: speed, step medians; then, untimed by the
// loop above, meshing and hole filling and each scene's accuracy.
nlohmann::json PipelineJson(const Pipeline& p, const Rig& rig, const std::vector<Scene>& scenes) {
  nlohmann::json j = {{"matcher", MatcherKindName(p.matcher)},
                      {"runtime_build_ms", p.build_ms},
                      {"objects", p.objects},
                      {"busy_s", p.busy_s},
                      {"objects_per_s", p.objects / p.busy_s},
                      {"cpu_ms_per_object", 1e3 * p.cpu_s / p.objects},
                      {"cores_busy", p.cpu_s / p.busy_s},
                      {"page_faults_per_object", double(p.page_faults) / p.objects}};
  for (const auto& [k, v] : p.steps) j["median_time_ms"][k] = Median(v);
  for (const Scene& s : scenes) {
    const Reconstruction rec = p.runtime->Process(s.images, true);
    nlohmann::json sj = ReconstructionJson(rec);
    sj["scene"] = s.name;
    if (!s.truth.empty()) {
      const CloudScore score = ScoreAgainstTruth(rec.cloud, s.truth, rig.num_modules());
      nlohmann::json acc = {
          {"merged", ErrorFiguresJson(score.all)},
          {"alignment_truth_from_cloud",
           {{"rotation_deg", score.truth_from_cloud.AngleDeg()},
            {"translation_mm",
             {score.truth_from_cloud.translation_mm().x(), score.truth_from_cloud.translation_mm().y(),
              score.truth_from_cloud.translation_mm().z()}}}}};
      for (size_t m = 0; m < score.per_module.size(); ++m)
        acc["module"].push_back(ErrorFiguresJson(score.per_module[m]));
      if (score.filled.points) acc["hole_fill"] = FilledJson(score);
      sj["accuracy"] = acc;
    }
    if (s.truth_maps) {
      const SceneScore score = ScoreScene(*p.runtime, rec, *s.truth_maps);
      sj["truth_fill"] = score.fill_all.fill();
      for (const FillFigures& f : score.fill) sj["truth_fill_per_module"].push_back(f.fill());
    }
    j["scenes"].push_back(sj);
  }
  return j;
}

void PrintPipeline(const nlohmann::json& j, const std::vector<Scene>& scenes) {
  std::printf(
      "%-17s %6.1f objects/s, %.0f CPU ms/object, %.2f cores busy, %.0f page faults/object  (median: total %.1f ms, "
      "modules %.1f ms, match m0 %.1f ms)\n",
      j["matcher"].get<std::string>().c_str(), j["objects_per_s"].get<double>(), j["cpu_ms_per_object"].get<double>(),
      j["cores_busy"].get<double>(), j["page_faults_per_object"].get<double>(),
      j["median_time_ms"]["total_point_cloud"].get<double>(), j["median_time_ms"]["modules"].get<double>(),
      j["median_time_ms"]["module0.match"].get<double>());
  // Module 0's steps in pipeline order (map order is alphabetical): where the time goes.
  std::printf("  module 0 median ms:");
  // match.grow_2 and match.line_index_3 run only on captures where the
  // second line-index pass moved something: their medians are over those captures.
  for (const char* step :
       {"rectify", "lit_region", "match.band", "match.sgm", "match.sgbm", "match.subpixel", "match.subpixel_dense",
        "match.line_index", "match.grow", "match.line_index_2", "match.grow_2", "match.line_index_3", "match.speckle",
        "match.surface_fit", "triangulate", "normals"}) {
    const std::string key = std::string("module0.") + step;
    if (j["median_time_ms"].contains(key)) std::printf(" %s %.1f", step, j["median_time_ms"][key].get<double>());
  }
  std::printf("\n");
  for (size_t k = 0; k < scenes.size(); ++k) {
    const nlohmann::json& s = j["scenes"][k];
    std::printf("  %-10s %7d points, fill %.1f%%", s["scene"].get<std::string>().c_str(), s["points"].get<int>(),
                100 * s["fill_rate"].get<double>());
    if (s.contains("truth_fill")) std::printf(" (truth fill %.1f%%)", 100 * s["truth_fill"].get<double>());
    if (s.contains("accuracy")) {
      const auto& a = s["accuracy"];
      std::printf(", merged %s", ErrorText(a["merged"], " mm").c_str());
      for (size_t m = 0; m < a["module"].size(); ++m) std::printf(", m%zu %s", m, ErrorText(a["module"][m]).c_str());
      std::printf("; aligned by %.4f deg, %.4f mm", a["alignment_truth_from_cloud"]["rotation_deg"].get<double>(),
                  std::hypot(a["alignment_truth_from_cloud"]["translation_mm"][0].get<double>(),
                             a["alignment_truth_from_cloud"]["translation_mm"][1].get<double>(),
                             a["alignment_truth_from_cloud"]["translation_mm"][2].get<double>()));
    }
    if (!scenes[k].truth_missing.empty()) std::printf("; %s", scenes[k].truth_missing.c_str());
    std::printf("; mesh+fill %.1f ms\n", s["time_ms"]["mesh_join"].get<double>() +
                                             s["time_ms"]["hole_fill"].get<double>() +
                                             s["modules"][0]["time_ms"].value("mesh", 0.0));
  }
}

}  // namespace

int RunBench(int argc, char** argv) {
  CLI::App app{
      "Throughput of the runtime on the default captures (2 modules, 4 images), run many times, side by side in "
      "the same run with two baselines built on OpenCV StereoSGBM (MODE_SGBM_3WAY, the same disparity range and "
      "ROI), everything after the correspondence step equal: 'opencv_sgbm_3way' replaces only our census SGM and "
      "its occupied-band pass (our filters, line index, growing and sub-pixel refinement follow); "
      "'opencv_sgbm_3way_standalone' replaces our whole correspondence stage (SGBM's own 1/16 px sub-pixel fit, "
      "uniqueness, left-right check and speckle filter), as OpenCV users run it. Reports objects/s, CPU ms and "
      "minor page faults per object (a fault is a fresh page the kernel zeroes and maps: far steadier than time on "
      "a shared machine), the cores kept busy (CPU time over wall time: 2 on two cores fully used), per-step median "
      "times (module 0's printed), peak memory (our runtime's own: the "
      "process's peak after running each capture once with only the libraries and captures loaded, before the "
      "truth and the baselines; and the whole bench process's), the speed ratio, and both pipelines' accuracy "
      "(after one best rigid alignment to the truth surface) and fill rate. Without --dataset it renders a "
      "built-in scene: a 50 mm sphere with the laser grids on the embedded default rig.\n\n"
      "Exit codes: 0 ok; 2 bad usage or input.\n\n"
      "Examples:\n  stereorig bench --runs 20\n"
      "  stereorig bench --dataset sim --scenes cup,sphere --rig calibrated.yaml --report bench.json",
      "stereorig bench"};
  std::string dataset, rig_path, options_path, report_path, scenes_arg = "cup,sphere,ballbar,plate,tuber";
  int runs = 20;
  CLI::Option* dataset_option =
      app.add_option("--dataset", dataset, "simulator dataset folder (scenes/<scene>/active, truth/)");
  app.add_option("--scenes", scenes_arg,
                 "with --dataset: comma-separated scenes; each one named must be in the dataset "
                 "(scenes/<name>/active), or the bench exits 2 before any run; by default, those of the five the "
                 "dataset holds (cup,sphere,ballbar,plate,tuber)")
      ->needs(dataset_option);
  app.add_option("--rig", rig_path, "rig file to reconstruct with (default: the dataset's truth/rig.yaml)");
  app.add_option("--options", options_path, "runtime options YAML");
  // Read as a count (cli_util.h): 1.5 or 99999999999 said "Could not convert".
  AddCountOption(app, "--runs", &runs, "passes over the scenes per pipeline");
  app.add_option("--report", report_path, "write everything as JSON here")->check(NonEmptyPath());
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  // Before minutes of runs; with a dataset and no --rig, its truth rig is
  // the input to protect.
  namespace fs = std::filesystem;
  const std::string rig_read =
      rig_path.empty() && !dataset.empty() ? (fs::path(dataset) / "truth" / "rig.yaml").string() : rig_path;
  if (!report_path.empty())
    ClaimRuntimeReport(
        {.path = report_path,
         .rig_path = rig_read,
         .rig_what = rig_path.empty() ? "the dataset's truth rig file (read without --rig)" : "the rig file (--rig)",
         .options_path = options_path,
         .more_inputs = DatasetInputs(dataset)});
  // Scenes the user named must all be there (a misspelt one used to be
  // skipped, and fewer scenes benched without a word); the default list
  // takes those the dataset holds.
  std::vector<std::string> scene_names = SplitSceneList(scenes_arg);
  if (!dataset.empty()) {
    CheckDatasetFolder(dataset, rig_path.empty());  // its own captures with --rig: no truth
    scene_names = ScenesToRun(dataset, scene_names, app.count("--scenes") > 0);
  }

  Rig rig;
  std::vector<Scene> scenes;
  if (dataset.empty()) {
    const SimulatedRig sim = MakeDefaultRig();
    rig = rig_path.empty() ? sim.rig : ReadRigFile(rig_path);
    SphereSceneSpec spec;
    spec.centre_mm = sim.world_from_module0.Inverse() * Eigen::Vector3d::Zero();
    spec.radius_mm = 25;
    scenes.push_back(
        {"sphere(builtin)", RenderSphereCapture(sim.rig, spec), SampleSphere(spec.centre_mm, spec.radius_mm, 0.2), {}});
  } else {
    rig = ReadRigFile(rig_read);
    // The truth fill and accuracy take the truth rig's module m for the
    // cloud's module m, as score does: a --rig of another layout was judged
    // against the wrong module's truth, exit 0. A line's own captures with
    // no truth rig have nothing to compare.
    const fs::path truth_rig = fs::path(dataset) / "truth" / "rig.yaml";
    if (!rig_path.empty() && fs::exists(truth_rig))
      RequireTruthRigLayout(rig, rig_path, ReadRigFile(truth_rig.string()), truth_rig.string(), "bench");
    for (const std::string& name : scene_names) {
      const fs::path capture = fs::path(dataset) / "scenes" / name / "active";
      scenes.push_back(Scene{name, LoadCapture(capture.string(), rig), {}, {}});
    }
  }
  const RuntimeOptions options = options_path.empty() ? RuntimeOptions{} : ReadRuntimeOptions(options_path);
  std::printf("bench: %zu scene(s), %d run(s) each, %d modules, %u hardware threads\n", scenes.size(), runs,
              rig.num_modules(), std::thread::hardware_concurrency());

  std::vector<Pipeline> pipelines;
  auto add_pipeline = [&](MatcherKind kind) {
    RuntimeOptions o = options;
    o.match.matcher = kind;
    const auto t0 = Clock::now();
    pipelines.push_back(Pipeline{kind, std::make_unique<Runtime>(rig, o), 0, 0, 0, 0, 0, {}});
    pipelines.back().build_ms = MsSince(t0);
  };
  // The runtime's own peak memory: so far the process holds the libraries,
  // the rig and the captures only; our runtime is built and runs every
  // capture once (mesh and hole filling included), before the truth, the
  // baselines' runtimes or their buffers exist. The process's peak now is
  // what a process running this runtime alone on these captures reaches.
  const double libraries_mb = ResidentMemoryMb();
  add_pipeline(MatcherKind::kCensusSgm);
  for (const Scene& s : scenes) pipelines[0].runtime->Process(s.images, true);
  const double runtime_peak_mb = PeakMemoryMb();
  std::printf(
      "peak memory of our runtime: %.0f MB (the process holding only the libraries and captures, %.0f MB, then our "
      "runtime built and run once on each capture)\n",
      runtime_peak_mb, libraries_mb);
  FlushStdout();
  if (!dataset.empty()) {
    namespace fs = std::filesystem;
    for (Scene& s : scenes) {
      const fs::path truth_dir = fs::path(dataset) / "truth" / "scenes" / s.name;
      const fs::path truth = truth_dir / "surface.ply";
      if (fs::exists(truth)) s.truth = ReadPlyPoints(truth.string());
      if (fs::exists(truth_dir / "lit_cam0.png")) s.truth_maps = ReadSceneTruth(dataset, s.name);
      // (Truth maps without the surface are refused by ReadSceneTruth.)
      if (!fs::exists(truth))
        s.truth_missing = "no truth (" + truth_dir.string() + "/): no accuracy, no truth fill";
      else if (s.truth.empty())
        s.truth_missing = "no point in the truth surface (" + truth.string() + "): no accuracy";
      else if (!s.truth_maps)
        s.truth_missing = "no truth maps (" + (truth_dir / "lit_cam0.png").string() + "): no truth fill";
      // A volume that misses the scene benches empty clouds: said as score says it.
      WarnIfVolumeMissesTruth("bench", s.name, s.truth, pipelines[0].runtime->volume_center_mm(),
                              options.volume_size_mm);
    }
  }
  const double loaded_mb = ResidentMemoryMb();  // + truth surfaces and maps, before the baselines' runtimes
  add_pipeline(MatcherKind::kOpenCvSgbm3Way);
  add_pipeline(MatcherKind::kOpenCvSgbm3WayStandalone);
  BenchInterleaved(pipelines, scenes, runs);
  const double bench_peak_mb = PeakMemoryMb();  // before scoring builds its k-d trees
  nlohmann::json report;
  report["ours"] = PipelineJson(pipelines[0], rig, scenes);
  PrintPipeline(report["ours"], scenes);
  report["baseline"] = PipelineJson(pipelines[1], rig, scenes);
  PrintPipeline(report["baseline"], scenes);
  report["baseline_standalone"] = PipelineJson(pipelines[2], rig, scenes);
  PrintPipeline(report["baseline_standalone"], scenes);
  auto objects_ratio = [&](const char* key) {
    return report["ours"]["objects_per_s"].get<double>() / report[key]["objects_per_s"].get<double>();
  };
  auto cpu_ratio_of = [&](const char* key) {
    return report[key]["cpu_ms_per_object"].get<double>() / report["ours"]["cpu_ms_per_object"].get<double>();
  };
  const double ratio = objects_ratio("baseline"), cpu_ratio = cpu_ratio_of("baseline");
  const double ratio_standalone = objects_ratio("baseline_standalone");
  const double cpu_ratio_standalone = cpu_ratio_of("baseline_standalone");
  report["speed_ratio_ours_over_sgbm"] = ratio;
  report["cpu_ratio_sgbm_over_ours"] = cpu_ratio;
  report["speed_ratio_ours_over_sgbm_standalone"] = ratio_standalone;
  report["cpu_ratio_sgbm_standalone_over_ours"] = cpu_ratio_standalone;
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) > 0) report["machine_load_average_1min"] = load[0];
  report["peak_memory_mb"] = PeakMemoryMb();
  report["peak_memory_while_timed_mb"] = bench_peak_mb;
  report["runtime_peak_memory_mb"] = runtime_peak_mb;
  report["memory_before_runtimes_mb"] = libraries_mb;
  report["memory_before_baselines_mb"] = loaded_mb;
  std::printf("speed ratio (ours / SGBM standalone pipeline): %.2fx wall, %.2fx CPU\n", ratio_standalone,
              cpu_ratio_standalone);
  std::printf(
      "speed ratio (ours / SGBM in our pipeline): %.2fx wall, %.2fx CPU; machine load average %.1f (other processes "
      "slow both pipelines)\n",
      ratio, cpu_ratio, load[0]);
  std::printf(
      "peak memory of our runtime %.0f MB; the whole bench process while timed %.0f MB (it also holds the truth "
      "surfaces and maps and three runtimes: %.0f MB before the baselines' runtimes were built), incl. scoring "
      "%.0f MB\n",
      runtime_peak_mb, bench_peak_mb, loaded_mb, PeakMemoryMb());
  if (!report_path.empty()) WriteFileAtomically(report_path, JsonReportText(report) + "\n");
  if (rig_path.empty()) WarnOfTruthRig("bench", dataset.empty() ? "the simulator's default rig" : rig_read);
  return kExitOk;
}

}  // namespace stereorig
