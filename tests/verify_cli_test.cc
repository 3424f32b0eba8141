// `stereorig verify` end to end through the binary: exit 0 on a cloud of the
// certified sphere, 1 on a sphere outside the MPE, 2 on bad input, and the
// JSON report's figures match the analytic truth.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/cli_runner.h"

namespace {

using stereorig::testing::Lines;
using stereorig::testing::RunCli;

// An ascii PLY of a sphere's two caps (what two facing modules see), exact.
std::string WriteSphere(const std::string& name, double radius_mm) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::vector<std::array<double, 3>> pts;
  for (int cap = 0; cap < 2; ++cap)
    for (double t = 0; t < 1.3; t += 0.02)
      for (double p = 0; p < 2 * M_PI; p += 0.05) {
        const double s = cap ? 1 : -1;
        pts.push_back({10 + radius_mm * std::sin(t) * std::cos(p), -5 + radius_mm * std::sin(t) * std::sin(p),
                       s * radius_mm * std::cos(t)});
      }
  std::ofstream f(path);
  f << "ply\nformat ascii 1.0\nelement vertex " << pts.size()
    << "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  f.precision(17);
  for (const auto& q : pts) f << q[0] << " " << q[1] << " " << q[2] << "\n";
  return path;
}

std::string WriteArtifact(const std::string& text) {
  const std::string path = ::testing::TempDir() + "/artifact.yaml";
  std::ofstream(path) << text;
  return path;
}

const char* kSphere =
    "format: stereorig-artifact\nversion: 1\nunits: mm\nname: test sphere\ntype: sphere\n"
    "diameter_mm: 38.1\ndiameter_uncertainty_mm: 0.002\n";

TEST(VerifyCli, PassFailAndReport) {
  const std::string artifact = WriteArtifact(kSphere);
  const std::string good = WriteSphere("good.ply", 19.05);
  const std::string report = ::testing::TempDir() + "/verify.json";
  std::filesystem::remove(report);
  auto r = RunCli("verify --artifact " + artifact + " --cloud " + good + " --cloud " + good + " --report " + report);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  std::ifstream f(report);
  const auto j = nlohmann::json::parse(f);
  EXPECT_TRUE(j["summary"]["pass"].get<bool>());
  EXPECT_EQ(j["positions"].size(), 2u);
  for (const auto& fig : j["positions"][0]["figures"]) EXPECT_LT(std::abs(fig["value_mm"].get<double>()), 0.005);

  // 1.6 mm too large in diameter: P_S = 1.6 > MPE 1.5 -> exit 1.
  const std::string big = WriteSphere("big.ply", 19.05 + 0.8);
  r = RunCli("verify --artifact " + artifact + " --cloud " + big);
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("FAIL"), std::string::npos);
}

TEST(VerifyCli, BadInputExitsTwoAndWritesNoReport) {
  const std::string good = WriteSphere("good2.ply", 19.05);
  const std::string report = ::testing::TempDir() + "/verify_bad.json";
  std::filesystem::remove(report);
  // An artifact file with a missing field.
  auto r = RunCli("verify --artifact " +
                  WriteArtifact("format: stereorig-artifact\nversion: 1\nunits: mm\ntype: ballbar\n"
                                "sphere_diameter_mm: 25.4\n") +
                  " --cloud " + good + " --report " + report);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("center_distance_mm: missing key"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(report));
  // A cloud with too few points on the artifact.
  const std::string tiny = ::testing::TempDir() + "/tiny.ply";
  std::ofstream(tiny) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                         "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  r = RunCli("verify --artifact " + WriteArtifact(kSphere) + " --cloud " + tiny + " --report " + report);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("tiny.ply"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(report));
}

}  // namespace
