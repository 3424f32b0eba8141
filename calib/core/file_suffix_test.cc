#include "calib/core/file_suffix.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

TEST(FileSuffix, LettersMatchWithoutCase) {
  for (const char* path : {"cloud.ply", "cloud.PLY", "dir.d/cloud.Ply", ".ply"})
    EXPECT_TRUE(EndsWithIgnoringCase(path, ".ply")) << path;
  EXPECT_TRUE(EndsWithIgnoringCase("mesh.STL", ".stl"));
}

TEST(FileSuffix, OnlyTheWholeSuffixAtTheEndCounts) {
  for (const char* path : {"cloud.ply.tmp", "cloud.plx", "cloudply", "ply", "", "cloud.ply "})
    EXPECT_FALSE(EndsWithIgnoringCase(path, ".ply")) << '"' << path << '"';
}

}  // namespace
}  // namespace stereorig
