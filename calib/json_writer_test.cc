// The report builder against nlohmann's own parser: what is written parses
// back to the same values, in the order given, with NaN and Inf as null and
// strings escaped.
#include "calib/json_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace stereorig {
namespace {

TEST(JsonWriter, WritesWhatAParserReadsBackInOrder) {
  JsonWriter j;
  j.BeginObject().String("source", "caps \"A\"\\\n\t\x01").Int("modules", 2).Bool("ok", true);
  j.Number("nan", std::nan("")).Number("inf", std::numeric_limits<double>::infinity());
  j.Number("third", 1.0 / 3).Numbers("xyz", {1.5, -2, 1e-300});
  j.BeginArray("views").BeginObject().Int("capture", 7).EndObject().Int(3).EndArray();
  j.BeginObject("zeta").EndObject().BeginObject("alpha").Number("rms_px", 0.25).EndObject();
  j.EndObject();
  const nlohmann::json back = nlohmann::json::parse(j.str());
  EXPECT_EQ(back["source"], "caps \"A\"\\\n\t\x01");
  EXPECT_EQ(back["modules"], 2);
  EXPECT_EQ(back["ok"], true);
  EXPECT_TRUE(back["nan"].is_null());
  EXPECT_TRUE(back["inf"].is_null());
  EXPECT_EQ(back["third"].get<double>(), 1.0 / 3);  // round-trips exactly
  EXPECT_EQ(back["xyz"], nlohmann::json({1.5, -2.0, 1e-300}));
  EXPECT_EQ(back["views"][0]["capture"], 7);
  EXPECT_EQ(back["views"][1], 3);
  EXPECT_EQ(back["alpha"]["rms_px"], 0.25);
  // Keys in the order given, not sorted: "zeta" before "alpha".
  EXPECT_LT(j.str().find("\"zeta\""), j.str().find("\"alpha\""));
  EXPECT_LT(j.str().find("\"source\""), j.str().find("\"modules\""));
}

}  // namespace
}  // namespace stereorig
