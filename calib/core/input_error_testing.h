// Test helpers for refusals: the message of the InputError a call throws,
// and a fresh scratch folder for a test that writes files.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>

#include "calib/core/input_error.h"

namespace stereorig::testing {

// The message of the InputError `call` throws, or "" if it throws none
// (any other exception passes through, and fails the test).
inline std::string InputErrorMessage(const std::function<void()>& call) {
  try {
    call();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// TempDir()/name, emptied and created: one per test.
inline std::string ScratchFolder(const std::string& name) {
  std::string dir = ::testing::TempDir() + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace stereorig::testing
