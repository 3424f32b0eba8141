// `stereorig match` end to end: a rendered pair with known disparity goes in
// as PNG files, the PFM that comes out is read back with OpenCV's own PFM
// codec (independent of ours) and compared with the truth.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

const std::string kBin = std::string(STEREORIG_BINARY_DIR) + "/stereorig";

int RunCli(const std::string& args) {
  const int status = std::system((kBin + " " + args + " >/dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(MatchCli, WritesAPfmThatMatchesTheTruth) {
  const std::string dir = ::testing::TempDir() + "/match_cli";
  std::filesystem::create_directories(dir);
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  ASSERT_TRUE(cv::imwrite(dir + "/L.png", pair.left));
  ASSERT_TRUE(cv::imwrite(dir + "/R.png", pair.right));
  const std::string out = dir + "/disp.pfm";
  std::filesystem::remove(out);
  ASSERT_EQ(RunCli("match --left " + dir + "/L.png --right " + dir + "/R.png --min-disparity 24 --num-disparities 64 "
                "--out " + out),
            0);
  const cv::Mat disp = cv::imread(out, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(disp.type(), CV_32FC1);
  ASSERT_EQ(disp.size(), pair.left.size());
  int valid = 0, total = 0, invalid_is_inf = 0, invalid = 0;
  double sum2 = 0;
  for (int y = 12; y < disp.rows - 12; ++y)
    for (int x = 70; x < disp.cols - 12; ++x) {
      ++total;
      const float d = disp.at<float>(y, x);
      if (!std::isfinite(d)) {
        ++invalid;
        invalid_is_inf += std::isinf(d) && d > 0;
        continue;
      }
      ++valid;
      sum2 += std::pow(d - pair.true_disparity_px.at<double>(y, x), 2);
    }
  EXPECT_EQ(invalid_is_inf, invalid);
  EXPECT_GT(valid, 0.97 * total);
  // Same bound as matcher_test's slanted plane (noise 2 DN + window model).
  EXPECT_LT(std::sqrt(sum2 / valid), 0.035);
  // Column 0 cannot match (its partner is off the right image): +inf.
  EXPECT_TRUE(std::isinf(disp.at<float>(100, 0)));
}

TEST(MatchCli, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = ::testing::TempDir() + "/match_cli_bad";
  std::filesystem::create_directories(dir);
  const std::string out = dir + "/disp.pfm";
  std::filesystem::remove(out);
  cv::imwrite(dir + "/small.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(3)));
  cv::imwrite(dir + "/big.png", cv::Mat(12, 10, CV_8UC1, cv::Scalar(3)));
  EXPECT_EQ(RunCli("match --left " + dir + "/missing.png --right " + dir + "/small.png --min-disparity 0 "
                "--num-disparities 16 --out " + out),
            2);
  EXPECT_EQ(RunCli("match --left " + dir + "/small.png --right " + dir + "/big.png --min-disparity 0 "
                "--num-disparities 16 --out " + out),
            2);
  EXPECT_EQ(RunCli("match --left " + dir + "/small.png --right " + dir + "/small.png --min-disparity 0 "
                "--num-disparities 1 --out " + out),
            2);
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace stereorig
