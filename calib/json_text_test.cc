#include "calib/json_text.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

// Bytes that are not UTF-8, in values and member names alike, are written
// as \xNN and the text parses back (nlohmann-json's dump threw on them);
// UTF-8 ('å', 4-byte sequences) and control characters (escaped by JSON
// itself) pass unchanged. Both document types the reports use.
TEST(JsonText, WritesBytesThatAreNotUtf8AsEscapesAndKeepsUtf8) {
  nlohmann::json doc = {{"path", "d\xE9/s.ply"},
                        {"k\xFF", {"k\xC3\xA5sa", "\xF0\x9F\x98\x80", "tab\t", "cut \xE2\x82"}},
                        {"overlong", "\xC0\xAF"}};
  const nlohmann::json back = nlohmann::json::parse(JsonReportText(doc));
  EXPECT_EQ(back["path"], "d\\xE9/s.ply");
  EXPECT_EQ(back["k\\xFF"], nlohmann::json({"k\xC3\xA5sa", "\xF0\x9F\x98\x80", "tab\t", "cut \\xE2\\x82"}));
  EXPECT_EQ(back["overlong"], "\\xC0\\xAF");
  nlohmann::ordered_json ordered = {{"z", "\xE8"}, {"a", 1}};
  EXPECT_EQ(JsonReportText(ordered), "{\n  \"z\": \"\\\\xE8\",\n  \"a\": 1\n}");
}

}  // namespace
}  // namespace stereorig
