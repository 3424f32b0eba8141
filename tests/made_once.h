// Inputs every test case of a binary shares (rendered datasets), made once
// per build of the binary. ctest runs each case in a process of its own
// (gtest_discover_tests), so a suite's SetUpTestSuite made the same renders
// again for every case: tune_cli_test rendered its six plates 14 times.
#pragma once

#include <functional>
#include <string>

namespace stereorig::testing {

// The folder `name` that `make` fills, made by the first caller and read by
// the others. It lies in this binary's scratch folder under the binary's
// build (its modification time), so a rebuilt simulator is never read
// through an older render, and earlier builds' folders are removed. `make`
// fills a folder of this process's own (the path it is given, not yet
// made), which is then renamed into place whole: two cases ctest -j starts
// together never read a half-made one, and the slower one's copy is
// removed. Where `make` records a test failure, its folder is returned as
// it is and not shared.
std::string MadeOnce(const std::string& name, const std::function<void(const std::string& dir)>& make);

}  // namespace stereorig::testing
