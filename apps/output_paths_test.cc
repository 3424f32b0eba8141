#include "apps/output_paths.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

using testing::InputErrorMessage;

std::string Scratch(const std::string& name) { return testing::ScratchFolder("output_paths_" + name); }

// A folder whose name is longer than the file system allows (255 on ext4)
// is refused by the claim itself, naming the path and the problem, before
// the command does any work: it used to be found only by Create, after it.
// Nothing is made. (The other claim-time test, a nearest existing folder
// this process may not write in, cannot be tested here: the tests run as
// root in CI, for whom access() grants everything.)
TEST(OutputPaths, AFolderNameTooLongForTheFileSystemIsRefusedWhenClaimed) {
  const std::string dir = Scratch("long_folder");
  const long name_max = pathconf(dir.c_str(), _PC_NAME_MAX);
  ASSERT_GT(name_max, 0) << "a file system without a name limit: nothing to test";
  const std::string too_long(name_max + 1, 'x');
  for (const std::string& folder : {dir + "/" + too_long, dir + "/new/" + too_long + "/deeper"}) {
    const std::string says = InputErrorMessage([&] { (void)OutputPaths().ClaimFolder(folder, "the test folder"); });
    EXPECT_EQ(says.rfind(folder + ": cannot create this folder for the test folder: File name too long", 0), 0u)
        << says;
    EXPECT_NE(says.find(std::to_string(name_max + 1) + " characters"), std::string::npos) << says;
  }
  EXPECT_FALSE(fs::exists(dir + "/new"));
  // A name of the longest length allowed is claimed, and made.
  FolderToCreate longest = OutputPaths().ClaimFolder(dir + "/new/" + std::string(name_max, 'y'), "the test folder");
  longest.Create();
  EXPECT_TRUE(fs::is_directory(dir + "/new/" + std::string(name_max, 'y')));
}

// The same test for a file claimed: its own name, in an existing folder or
// in one the command creates (claimed without the folder test).
TEST(OutputPaths, AFileNameTooLongForTheFileSystemIsRefusedWhenClaimed) {
  const std::string dir = Scratch("long_file");
  const long name_max = pathconf(dir.c_str(), _PC_NAME_MAX);
  ASSERT_GT(name_max, 0) << "a file system without a name limit: nothing to test";
  const std::string too_long = std::string(name_max - 4, 'x') + ".json";
  const std::string file = dir + "/" + too_long;
  std::string says = InputErrorMessage([&] { OutputPaths().Claim(file, "the report (--report)"); });
  EXPECT_EQ(says.rfind(file + ": cannot write the report (--report): File name too long", 0), 0u) << says;
  OutputPaths outputs;
  (void)outputs.ClaimFolder(dir + "/out", "the output folder");
  says = InputErrorMessage([&] { outputs.Claim(dir + "/out/" + too_long, "a capture's report", false); });
  EXPECT_NE(says.find("cannot write a capture's report: File name too long"), std::string::npos) << says;
  EXPECT_EQ(InputErrorMessage([&] { outputs.Claim(dir + "/out/" + too_long.substr(1), "a capture's report", false); }),
            "");
}

}  // namespace
}  // namespace stereorig
