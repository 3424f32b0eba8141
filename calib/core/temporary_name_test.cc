#include "calib/core/temporary_name.h"

#include <gtest/gtest.h>

#include <string>

namespace stereorig {
namespace {

bool StartsWith(const std::string& s, const std::string& start) { return s.rfind(start, 0) == 0; }
bool EndsWith(const std::string& s, const std::string& end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}

// Whether `s` is whole UTF-8: every lead byte followed by as many
// continuation bytes as it announces.
bool IsWholeUtf8(const std::string& s) {
  for (size_t i = 0; i < s.size();) {
    const unsigned char lead = static_cast<unsigned char>(s[i]);
    const size_t length = lead < 0x80           ? 1
                          : (lead >> 5) == 0x6  ? 2
                          : (lead >> 4) == 0xE  ? 3
                          : (lead >> 3) == 0x1E ? 4
                                                : 0;
    if (length == 0 || i + length > s.size()) return false;
    for (size_t k = 1; k < length; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += length;
  }
  return true;
}

TEST(TemporaryName, AShortNameIsKeptWhole) {
  EXPECT_EQ(TemporaryName(".tmp-42-0-", "cloud.ply"), ".tmp-42-0-cloud.ply");
  EXPECT_EQ(TemporaryName(".", "ds", ".tmp-42"), ".ds.tmp-42");
}

// A legal name of up to 255 bytes, tagged, fits in 255 bytes: the tag and
// the extension whole, the name's start cut. (Before, ".tmp-<pid>-<n>-"
// before a 250-byte name made a name the file system refused.)
TEST(TemporaryName, ALongNameIsCutToFitKeepingTheTagAndTheExtension) {
  for (const size_t name_bytes : {240u, 250u, 255u}) {
    const std::string name = std::string(name_bytes - 5, 'r') + ".json";
    const std::string tmp = TemporaryName(".tmp-1234567-89-", name);
    EXPECT_EQ(tmp.size(), kMaxNameBytes) << name_bytes;
    EXPECT_TRUE(StartsWith(tmp, ".tmp-1234567-89-rrr")) << tmp;
    EXPECT_TRUE(EndsWith(tmp, "r.json")) << tmp;
  }
  const std::string folder = TemporaryName(".", std::string(250, 'y'), ".tmp-1234567");
  EXPECT_EQ(folder.size(), kMaxNameBytes);
  EXPECT_TRUE(StartsWith(folder, ".yyy")) << folder;
  EXPECT_TRUE(EndsWith(folder, "y.tmp-1234567")) << folder;
}

// An "extension" too long to keep apart (a dot early in a long name) is
// cut like the rest, from the end: the tag must fit whatever the name.
TEST(TemporaryName, ALongExtensionIsCutFromItsEnd) {
  const std::string name = "a." + std::string(253, 'b');
  const std::string tmp = TemporaryName(".tmp-1-2-", name);
  EXPECT_EQ(tmp.size(), kMaxNameBytes);
  EXPECT_EQ(tmp, ".tmp-1-2-" + name.substr(0, kMaxNameBytes - 9));
}

// The cut never splits a UTF-8 character (2, 3 and 4 bytes long), at any
// offset the tag's length puts it: the name stays readable and valid for
// tools that check it; at most 3 bytes of room are given up for that.
TEST(TemporaryName, TheCutNeverSplitsAUtf8Character) {
  for (const std::string character : {"\xC3\xA9", "\xE2\x82\xAC", "\xF0\x9F\x98\x80"}) {
    std::string stem;
    while (stem.size() < 260) stem += character;
    for (size_t tag_bytes = 5; tag_bytes < 12; ++tag_bytes) {
      std::string tag(tag_bytes, 't');
      tag[0] = '.';  // (not "." + std::string(...): GCC 12 warns of a memcpy overlap there, wrongly)
      const std::string tmp = TemporaryName(tag, stem + ".png");
      EXPECT_LE(tmp.size(), kMaxNameBytes);
      EXPECT_GE(tmp.size(), kMaxNameBytes - 3);
      EXPECT_TRUE(IsWholeUtf8(tmp)) << "tag " << tag_bytes << " bytes, character " << character.size() << " bytes";
      EXPECT_TRUE(EndsWith(tmp, character + ".png")) << tmp;
    }
  }
}

// Bytes that are not UTF-8 (a name from an older system's encoding) are cut
// where the room ends: the name still fits.
TEST(TemporaryName, BytesThatAreNotUtf8AreCutWhereTheyFall) {
  const std::string latin1(300, '\xA9');  // continuation bytes only
  EXPECT_EQ(TemporaryName(".tmp-1-2-", latin1).size(), kMaxNameBytes);
}

}  // namespace
}  // namespace stereorig
