// `stereorig bench` end to end on its built-in scene (a 50 mm sphere under
// the laser grids on the embedded default rig, rendered with its truth):
// the report holds both pipelines' figures, our accuracy against the
// simulator's truth surface, the runtime's peak memory, and a page-fault
// count per object that shows the process keeps its heap between captures
// (heap_retention.h). No time is asserted: speed is the bench's to report.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <utility>

#include "calib/core/rig_file.h"
#include "datasets/default_rig.h"
#include "tests/cli_runner.h"
#include "tests/sim_scene.h"

namespace stereorig {
namespace {

using testing::RunCli;

TEST(BenchCli, ReportsBothPipelinesAccuracyAndAHeapKeptBetweenCaptures) {
  const std::string report = ::testing::TempDir() + "/bench_cli_" + std::to_string(getpid()) + ".json";
  std::filesystem::remove(report);
  const testing::Result r = RunCli("bench --runs 2 --report " + report);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("page faults/object"), std::string::npos) << r.out;
  // Progress on stderr after each run (a dataset's runs take ~1 min).
  EXPECT_NE(r.err.find("bench: [1/2] run 1 timed; so far ours "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bench: [2/2] run 2 timed"), std::string::npos) << r.err;
  std::ifstream f(report);
  ASSERT_TRUE(f.good()) << report;
  const nlohmann::json j = nlohmann::json::parse(f);
  std::filesystem::remove(report);
  for (const char* p : {"ours", "baseline", "baseline_standalone"}) {
    ASSERT_TRUE(j.contains(p)) << p;
    EXPECT_EQ(j[p]["objects"].get<int>(), 2) << p;  // 1 scene x 2 runs
    EXPECT_GT(j[p]["objects_per_s"].get<double>(), 0) << p;
    EXPECT_GT(j[p]["cpu_ms_per_object"].get<double>(), 0) << p;
    // CPU over wall time: the same seconds as the two figures above, and
    // no more cores than the machine has (rusage's clock ticks aside).
    const double cores = j[p]["cores_busy"].get<double>();
    EXPECT_NEAR(cores, j[p]["cpu_ms_per_object"].get<double>() * j[p]["objects_per_s"].get<double>() / 1000, 1e-9) << p;
    EXPECT_GT(cores, 0) << p;
    EXPECT_LT(cores, std::thread::hardware_concurrency() + 0.5) << p;
  }
  EXPECT_NE(r.out.find("cores busy"), std::string::npos) << r.out;
  // Against the simulator's truth surface (independent of the runtime):
  // measured 0.010 mm mean |e|; the issue's single-module goal is 0.1 mm.
  const nlohmann::json& merged = j["ours"]["scenes"][0]["accuracy"]["merged"];
  EXPECT_GT(merged["points"].get<int>(), 10000);
  EXPECT_LT(merged["mean_abs_mm"].get<double>(), 0.1);
#if !defined(__SANITIZE_ADDRESS__)  // ASan's allocator and shadow memory change both figures
  // The issue's memory bound (measured 124 MB on this scene).
  EXPECT_LE(j["runtime_peak_memory_mb"].get<double>(), 300);
  // With the heap kept: 36 faults per object measured; with glibc's
  // defaults 6 000-7 900 (each capture's ~25 MB of maps faulted in again,
  // 4 KB at a time). A tenth of that is the line between the two.
  EXPECT_LT(j["ours"]["page_faults_per_object"].get<double>(), 600);
#endif
}

// A --report that cannot be written is refused before the runs (which take
// minutes on a dataset), not after them: nothing measured is printed.
TEST(BenchCli, AReportInAMissingFolderExitsTwoBeforeAnyRun) {
  const std::string report = ::testing::TempDir() + "/no_such_folder_" + std::to_string(getpid()) + "/b.json";
  const testing::Result r = RunCli("bench --runs 1 --report " + report);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(report), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("objects/s"), std::string::npos) << r.out;
}

// With --dataset and no --rig, the bench reads the dataset's truth rig: a
// --report at that path would replace it. Refused before any run (the
// dataset holds nothing else: only the check can name the report), the rig
// file left as it was.
TEST(BenchCli, AReportOverTheDatasetsTruthRigIsRefused) {
  const std::string dataset = ::testing::TempDir() + "/bench_truth_rig_" + std::to_string(getpid());
  std::filesystem::create_directories(dataset + "/truth");
  const std::string rig = dataset + "/truth/rig.yaml";
  { std::ofstream(rig) << "the truth rig\n"; }
  const testing::Result r = RunCli("bench --runs 1 --dataset " + dataset + " --report " + rig);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(rig + ": is the dataset's truth rig file (read without --rig)"), std::string::npos) << r.err;
  std::ifstream f(rig);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), "the truth rig\n");
  std::filesystem::remove_all(dataset);
}

// Scenes named with --scenes must all be in the dataset: a misspelt one
// exits 2 before any work (it used to be skipped, and fewer scenes benched
// without a word), naming the dataset's scene folder and every missing
// scene. With the default list, scenes the dataset lacks are still skipped.
// The dataset holds only an (empty) cup capture and a truth rig that is not
// one: a run that gets past the scene check stops at the rig, before any
// image is read.
TEST(BenchCli, AMissingSceneNamedInScenesExitsTwoBeforeAnyRun) {
  const std::string dataset = ::testing::TempDir() + "/bench_scenes_" + std::to_string(getpid());
  std::filesystem::remove_all(dataset);
  std::filesystem::create_directories(dataset + "/scenes/cup/active");
  std::filesystem::create_directories(dataset + "/scenes/sphere/passive");  // no active capture: not a scene to bench
  std::filesystem::create_directories(dataset + "/truth");
  { std::ofstream(dataset + "/truth/rig.yaml") << "not a rig\n"; }
  const std::string bench = "bench --runs 1 --dataset " + dataset;
  const std::pair<std::string, std::string> refused[] = {
      {" --scenes cup,spher", dataset + "/scenes/spher: no such scene in the dataset (--scenes)"},
      {" --scenes sphere", dataset + "/scenes/sphere: no such scene in the dataset (--scenes)"},
      {" --scenes spher,cup,ballbal", dataset + "/scenes: no such scenes in the dataset (--scenes): spher, ballbal"},
      {" --scenes cup,,sphere", "--scenes cup,,sphere: an empty scene name"},
      {" --scenes cup,", "--scenes cup,: an empty scene name"},
      {" --scenes cup,cup", "--scenes cup,cup: names 'cup' twice"},
      {" --scenes cup/", "--scenes cup/: 'cup/' is not a scene name"}};
  for (const auto& [scenes, says] : refused) {
    const testing::Result r = RunCli(bench + scenes);
    EXPECT_EQ(r.code, 2) << scenes;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("objects/s"), std::string::npos) << r.out;
  }
  // Every named scene there, or the default list: on to the rig file.
  for (const std::string scenes : {" --scenes cup", ""}) {
    const testing::Result r = RunCli(bench + scenes);
    EXPECT_EQ(r.code, 2) << scenes;
    EXPECT_NE(r.err.find(dataset + "/truth/rig.yaml"), std::string::npos) << scenes << ": " << r.err;
    EXPECT_EQ(r.err.find("no such scene"), std::string::npos) << scenes << ": " << r.err;
  }
  // A line's own captures, laid out as scenes/<name>/active, with its
  // calibrated rig: no truth/ is needed (only without --rig, whose default
  // is truth/rig.yaml). On to that rig file here too.
  std::filesystem::remove_all(dataset + "/truth");
  { std::ofstream(dataset + "/own_rig.yaml") << "not a rig\n"; }
  const testing::Result own = RunCli(bench + " --scenes cup --rig " + dataset + "/own_rig.yaml");
  EXPECT_EQ(own.code, 2);
  EXPECT_NE(own.err.find(dataset + "/own_rig.yaml"), std::string::npos) << own.err;
  const testing::Result no_truth = RunCli(bench + " --scenes cup");
  EXPECT_NE(no_truth.err.find(dataset + ": is not a simulator dataset: it has no truth/ folder"), std::string::npos)
      << no_truth.err;
  std::filesystem::remove_all(dataset);
}

// bench, as score, takes the truth rig's module m (its fill target and
// depth) for the cloud's module m: a --rig pairing other cameras in its
// modules (another layout's: module 0 on cameras 2 and 3) had its truth
// fill and accuracy taken against the wrong module's truth, exit 0. Refused
// before any run, naming both rigs, with score's check (cli_util.h). The
// truth rig's own layout, and any layout on a line's own captures (no
// truth/rig.yaml), go on: to the capture here, an empty folder.
TEST(BenchCli, ARigWhoseModulesPairOtherCamerasThanTheTruthsIsRefusedBeforeAnyRun) {
  namespace fs = std::filesystem;
  const std::string dataset = ::testing::TempDir() + "/bench_other_layout_" + std::to_string(getpid());
  fs::remove_all(dataset);
  fs::create_directories(dataset + "/scenes/cup/active");
  fs::create_directories(dataset + "/truth");
  WriteRigFile(MakeDefaultRig().rig, dataset + "/truth/rig.yaml");
  const std::string other = dataset + "/other_layout.yaml";
  WriteRigFile(testing::DefaultRigInAnotherLayout(), other);
  const std::string bench = "bench --runs 1 --dataset " + dataset + " --scenes cup --rig ";
  const testing::Result r = RunCli(bench + other);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(other + ": module 0 has cameras 2 and 3; in the dataset's truth rig (" + dataset +
                       "/truth/rig.yaml) module 0 has cameras 0 and 1: bench compares each module with the truth's "
                       "of its number"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out.find("objects/s"), std::string::npos) << r.out;
  const std::string to_capture = dataset + "/scenes/cup/active/cam0.png: missing camera image";
  const testing::Result same = RunCli(bench + dataset + "/truth/rig.yaml");
  EXPECT_EQ(same.code, 2);
  EXPECT_NE(same.err.find(to_capture), std::string::npos) << same.err;
  fs::remove_all(dataset + "/truth");
  const testing::Result own = RunCli(bench + other);
  EXPECT_EQ(own.code, 2);
  EXPECT_NE(own.err.find(to_capture), std::string::npos) << own.err;
  fs::remove_all(dataset);
}

// A measurement volume that misses a scene, and a run without --rig (the
// truth rig read): bench and score warn of each in one line on stderr. The
// volume's line names the scene and both distances, on stderr (a warning:
// stdout carries the results; bench used to print it on stdout, score on
// stdout within the scene's figures). The sphere's centre is ~33 mm to the
// side of module 0 and ~205 mm ahead of it; a 150 mm wide volume centred
// 200 mm to the side (283 mm from module 0) holds none of it (and still
// projects into the images: the runtime builds). One scene, one run, empty
// clouds: a few seconds. (The default volume, which holds the sphere, would
// add ~10 s of scoring.)
TEST(BenchCli, BenchAndScoreWarnOnStderrOfAVolumeThatMissesAScenesTruthAndOfTheTruthRig) {
  const std::string dataset = testing::SimulateOneScene("sphere", 1, "bench_volume");
  const std::string options = dataset + "/volume_beside.yaml";
  { std::ofstream(options) << "volume_center_mm: [200, 0, 200]\n"; }
  for (const std::string command : {"bench --runs 1", "score --no-passive"}) {
    const testing::Result missed = RunCli(command + " --dataset " + dataset + " --scenes sphere --options " + options);
    ASSERT_EQ(missed.code, 0) << command << ": " << missed.err;
    // The scene's distance is the simulator's (about 206 mm): any number.
    const std::regex warning(command.substr(0, command.find(' ')) +
                             ": the measurement volume holds 0% of sphere's truth surface: its centre is 283 mm from "
                             "module 0, the scene's [0-9]+ mm; set working_distance_mm \\(or volume_center_mm\\) in "
                             "--options\n");
    EXPECT_TRUE(std::regex_search(missed.err, warning)) << command << ": " << missed.err;
    EXPECT_EQ(missed.out.find("measurement volume"), std::string::npos) << command << ": " << missed.out;
    // Without --rig the dataset's truth rig is read: said on stderr too
    // (score used to print it on stdout, bench not at all); with the same
    // file given as --rig, nothing.
    const std::string truth_rig = dataset + "/truth/rig.yaml";
    const std::string says = command.substr(0, command.find(' ')) + ": warning: no --rig: the figures above are " +
                             "the TRUTH rig's (" + truth_rig + ")";
    EXPECT_NE(missed.err.find(says), std::string::npos) << command << ": " << missed.err;
    EXPECT_EQ(missed.out.find("TRUTH"), std::string::npos) << command << ": " << missed.out;
    const testing::Result given =
        RunCli(command + " --dataset " + dataset + " --scenes sphere --options " + options + " --rig " + truth_rig);
    ASSERT_EQ(given.code, 0) << command << ": " << given.err;
    EXPECT_EQ(given.err.find("no --rig"), std::string::npos) << command << ": " << given.err;
  }
  std::filesystem::remove_all(dataset);
}

// A dataset scene without truth (truth/scenes/<scene>/: a line's own
// captures benched with their rig), or without its truth maps, is benched,
// and its line says what it lacks: the accuracy and the truth fill used to
// be left out without a word, as if the scene had none to give. Each
// pipeline's line says it. The volume beside the scene keeps the run to
// empty clouds: a few seconds.
TEST(BenchCli, ASceneWithoutTruthSaysSoOnItsLine) {
  namespace fs = std::filesystem;
  const std::string dataset = testing::SimulateOneScene("sphere", 1, "bench_no_truth");
  const std::string options = dataset + "/volume_beside.yaml";
  { std::ofstream(options) << "volume_center_mm: [200, 0, 200]\n"; }
  const std::string bench = "bench --runs 1 --dataset " + dataset + " --scenes sphere --options " + options;
  auto times_said = [](const std::string& out, const std::string& says) {
    int n = 0;
    for (size_t at = out.find(says); at != std::string::npos; at = out.find(says, at + 1)) ++n;
    return n;
  };
  const std::string truth = dataset + "/truth/scenes/sphere";
  fs::remove(truth + "/lit_cam0.png");
  const testing::Result no_maps = RunCli(bench);
  ASSERT_EQ(no_maps.code, 0) << no_maps.err;
  EXPECT_EQ(times_said(no_maps.out, "; no truth maps (" + truth + "/lit_cam0.png): no truth fill"), 3) << no_maps.out;
  EXPECT_EQ(times_said(no_maps.out, ", merged "), 3) << no_maps.out;  // its surface is there: accuracy
  fs::remove_all(truth);
  const testing::Result none = RunCli(bench);
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(times_said(none.out, "; no truth (" + truth + "/): no accuracy, no truth fill; mesh+fill"), 3) << none.out;
  fs::remove_all(dataset);
}

// Without --scenes, score and bench take those of the five default scenes
// the dataset holds: score used to require all five, and refused a dataset
// of one scene with "no such scenes in the dataset (--scenes): cup, ballbar,
// plate, tuber" though no --scenes was given. A dataset holding none of them
// is refused in one line that says so. The volume beside the scene keeps
// the run to empty clouds: a few seconds.
TEST(BenchCli, BenchAndScoreWithoutScenesTakeTheDefaultScenesTheDatasetHolds) {
  namespace fs = std::filesystem;
  const std::string dataset = testing::SimulateOneScene("sphere", 1, "bench_default_scenes");
  const std::string options = dataset + "/volume_beside.yaml";
  { std::ofstream(options) << "volume_center_mm: [200, 0, 200]\n"; }
  const std::string commands[] = {"score --no-passive", "bench --runs 1"};
  for (const std::string& command : commands) {
    const testing::Result r = RunCli(command + " --dataset " + dataset + " --options " + options);
    EXPECT_EQ(r.code, 0) << command << ": " << r.err;
    EXPECT_EQ(r.err.find("no such scene"), std::string::npos) << command << ": " << r.err;
    EXPECT_NE(r.out.find("sphere"), std::string::npos) << command << ": " << r.out;
    EXPECT_EQ(r.out.find("cup"), std::string::npos) << command << ": " << r.out;
  }
  // Named scenes are still all required.
  for (const std::string& command : commands) {
    const testing::Result r = RunCli(command + " --dataset " + dataset + " --scenes sphere,cup");
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_EQ(testing::Lines(r.err), 1) << command << ": " << r.err;
    EXPECT_NE(r.err.find(dataset + "/scenes/cup: no such scene in the dataset (--scenes)"), std::string::npos)
        << command << ": " << r.err;
  }
  fs::rename(dataset + "/scenes/sphere", dataset + "/scenes/ball");
  for (const std::string& command : commands) {
    const testing::Result r = RunCli(command + " --dataset " + dataset);
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_EQ(testing::Lines(r.err), 1) << command << ": " << r.err;
    EXPECT_NE(r.err.find(dataset + "/scenes: holds none of the default scenes (cup, sphere, ballbar, plate, tuber, "
                                   "each a folder <name>/active): name the dataset's scenes with --scenes"),
              std::string::npos)
        << command << ": " << r.err;
  }
  fs::remove_all(dataset);
}

// The key paths of a JSON value ("scenes[].merged.std_mm"), arrays by their
// first element; an object keyed by PixelStatus names (target_px_lost_by)
// is one key.
void KeyPaths(const nlohmann::json& j, const std::string& path, std::set<std::string>* paths) {
  if (j.is_array() && !j.empty() && j[0].is_structured()) return KeyPaths(j[0], path + "[]", paths);
  if (!path.empty()) paths->insert(path);
  if (!j.is_object() || path.ends_with("target_px_lost_by")) return;
  for (const auto& [key, value] : j.items()) KeyPaths(value, path.empty() ? key : path + "." + key, paths);
}

// score's per-module figures carry their unit as the merged ones do: they
// read "m0 fill 94.1% |e| 0.0346 std 0.0443; m1 ..." with "mm" only on the
// merged figures. And every key of its --report is in docs/reconstruct.md's
// table ("Score report JSON"), which it had none of ("write everything as
// JSON"). The sphere under the default volume: any numbers (a few seconds).
// Its passive points are scored, not only counted.
TEST(BenchCli, ScoresPerModuleFiguresSayTheirUnitAndEveryKeyOfItsReportIsDocumented) {
  const std::string dataset = testing::SimulateOneScene("sphere", 1, "score_units");
  const std::string report = dataset + "/score.json";
  const testing::Result r =
      RunCli("score --dataset " + dataset + " --scenes sphere --rig " + dataset + "/truth/rig.yaml --report " + report);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* module : {"m0", "m1"})
    EXPECT_TRUE(std::regex_search(
        r.out, std::regex(std::string("; ") + module + " fill +[0-9.]+% \\|e\\| [0-9.]+ std [0-9.]+ mm[;\n]")))
        << module << ": " << r.out;
  // The passive cloud's points are scored too, every one of them (the ratio
  // counts points, right or wrong).
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("; passive [0-9]+ points \\([0-9]+% within 0.5 mm, \\|e\\| [0-9.]+ mm; active/passive ")))
      << r.out;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  ASSERT_GT(j["scenes"][0]["passive_points"].get<int>(), 0) << "the sphere's passive capture made no point";
  EXPECT_EQ(j["scenes"][0]["passive"]["points"], j["scenes"][0]["passive_points"]);
  std::set<std::string> written;
  KeyPaths(j, "", &written);
  ASSERT_TRUE(written.contains("scenes[].modules[].accuracy.std_mm")) << "the run wrote no module figures";
  std::ifstream docs(std::string(STEREORIG_SOURCE_DIR) + "/docs/reconstruct.md");
  const std::string text(std::istreambuf_iterator<char>(docs), {});
  const size_t from = text.find("### Score report JSON"), to = text.find("\n#", from + 1);
  ASSERT_NE(from, std::string::npos);
  const std::string table = text.substr(from, to - from);
  for (const std::string& key : written) {
    // A row documents its key and, by "keys as merged's / the scene's
    // fill", the same figures under accuracy, passive, filled and
    // modules[].fill.
    const std::string row = "| `" + key + "` |";
    const std::string as_merged = std::regex_replace(
        key,
        std::regex("^scenes\\[\\]\\.(modules\\[\\]\\.accuracy|passive|filled(\\.by_distance_to_measured\\[\\])?)\\."),
        "scenes[].merged.");
    const std::string as_fill =
        std::regex_replace(key, std::regex("^scenes\\[\\]\\.modules\\[\\]\\.fill\\."), "scenes[].fill.");
    EXPECT_TRUE(table.find(row) != std::string::npos || table.find("| `" + as_merged + "` |") != std::string::npos ||
                table.find("| `" + as_fill + "` |") != std::string::npos)
        << key << " is not in docs/reconstruct.md's score report table";
  }
  std::filesystem::remove_all(dataset);
}

// A damaged truth map is bad input named in one line, by bench and score
// alike: they read the simulator's truth maps through the checked reader
// (reconstruct/image_file.h) as every image input. A lit map cut short used
// to reach imread, which let libpng print "libpng error: Read Error" before
// the error; a folder where a depth map belongs read as "cannot read it".
TEST(BenchCli, BenchAndScoreNameADamagedTruthMapInOneLine) {
  namespace fs = std::filesystem;
  const std::string dataset = testing::SimulateOneScene("sphere", 1, "bench_truth_map");
  const std::string truth = dataset + "/truth/scenes/sphere/";
  auto expect_named = [&](const std::string& says) {
    for (const std::string command : {"bench --runs 1", "score --no-passive"}) {
      const testing::Result r = RunCli(command + " --dataset " + dataset + " --scenes sphere");
      EXPECT_EQ(r.code, 2) << command << ": " << r.err;
      EXPECT_EQ(testing::Lines(r.err), 1) << command << ": " << r.err;
      EXPECT_NE(r.err.find(says), std::string::npos) << command << ": " << r.err;
    }
  };
  const std::string lit = truth + "lit_cam1.png", whole = dataset + "/lit_cam1_whole.png";
  fs::copy_file(lit, whole);
  fs::resize_file(lit, fs::file_size(lit) / 2);
  expect_named(lit + ": a PNG cut short or damaged (its IDAT chunk at byte 33 is longer than the rest of the file");
  fs::rename(whole, lit);
  fs::remove(truth + "depth_cam2.tiff");
  fs::create_directory(truth + "depth_cam2.tiff");
  expect_named(truth + "depth_cam2.tiff: is a folder, not a file");
  fs::remove_all(dataset);
}

// --runs is a count: each value that is not one is refused by the flag's
// name and what it must be, before any run ("Could not convert: --runs =
// 1.5" was CLI11's word for a fraction or a number past an int).
TEST(BenchCli, RunsThatAreNoCountAreRefusedByTheFlag) {
  const std::pair<std::string, std::string> refused[] = {
      {"0", "must be >= 1, got 0"},
      {"-3", "must be >= 1, got -3"},
      {"1.5", "must be a whole number >= 1, got 1.5"},
      {"99999999999", "must be at most 2147483647, got 99999999999"}};
  for (const auto& [runs, says] : refused) {
    const testing::Result r = RunCli("bench --runs " + runs);
    EXPECT_EQ(r.code, 2) << runs;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("stereorig bench: --runs: " + says), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("objects/s"), std::string::npos) << r.out;
  }
}

// --scenes picks scenes of a --dataset; without one (the built-in sphere)
// it would be ignored: refused instead.
TEST(BenchCli, ScenesWithoutADatasetIsRefused) {
  const testing::Result r = RunCli("bench --runs 1 --scenes cup");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--scenes requires --dataset"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("objects/s"), std::string::npos) << r.out;
}

// A dataset path that is not UTF-8 (a Latin-1 'é', the one byte E9) goes
// into score's report with that byte written as \xE9 (calib/json_text.h),
// the report valid JSON: the report's writer threw (nlohmann-json's
// type_error 316) after the figures were printed, an abort (exit 134) with
// no report.
TEST(BenchCli, ScoreWritesALatin1DatasetPathIntoItsReportEscaped) {
  const std::string simulated = testing::SimulateOneScene("sphere", 1, "score_latin1");
  const std::string dataset = simulated + "_ds\xE9";
  std::filesystem::remove_all(dataset);
  std::filesystem::rename(simulated, dataset);
  const std::string report = dataset + "/score.json";
  const testing::Result r =
      RunCli("score --dataset '" + dataset + "' --scenes sphere --no-passive --report '" + report + "'");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  std::ifstream f(report);
  ASSERT_TRUE(f.good()) << "no report";
  const nlohmann::json j = nlohmann::json::parse(f);  // throws on text that is not UTF-8
  EXPECT_EQ(j["dataset"].get<std::string>(), simulated + "_ds\\xE9");
  std::filesystem::remove_all(dataset);
}

}  // namespace
}  // namespace stereorig
