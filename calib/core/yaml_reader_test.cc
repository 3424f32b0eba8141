#include "calib/core/yaml_reader.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

using testing::InputErrorMessage;

TEST(YamlMap, NamesFileAndKeyInEveryError) {
  YamlMap m = YamlMap::LoadString("a: 1\nb: [1, 2]\nc: {d: .nan}\ne: text\n", "f.yaml");
  EXPECT_EQ(m.GetDouble("a"), 1.0);
  EXPECT_EQ(InputErrorMessage([&] { m.GetDoubles("b", 3); }), "f.yaml: b: expected 3 numbers, got 2");
  EXPECT_EQ(InputErrorMessage([&] { m.GetMap("c").GetDouble("d"); }), "f.yaml: c.d: NaN or Inf is not allowed");
  EXPECT_EQ(InputErrorMessage([&] { m.GetDouble("e"); }), "f.yaml: e: expected a number, got 'text'");
  EXPECT_EQ(InputErrorMessage([&] { m.GetDouble("zz"); }), "f.yaml: zz: missing key");
}

// A wrong type is an error (docs/formats.md): a quoted number is a string
// (a rig file's `version: "2"`, a target file's `corners_x: "11"`), and
// YAML 1.1's yes/no/on/off are not the documented true/false (a target
// file's `double_sided: yes`). yaml-cpp converts all of them on request;
// the reader did too. Plain numbers and YAML 1.2's booleans still read.
TEST(YamlMap, QuotedNumbersAndYamlOneOneBooleansAreWrongTypes) {
  YamlMap m = YamlMap::LoadString(
      "version: \"2\"\ncorners_x: '11'\nsize: \"9.5\"\nids: [1, \"2\"]\ndouble_sided: yes\nb2: off\nb3: \"true\"\n"
      "n: 2\nx: 9.5\nt: true\nf: False\nname: \"12\"\n",
      "f.yaml");
  EXPECT_EQ(InputErrorMessage([&] { m.GetInt("version"); }),
            "f.yaml: version: expected an integer, got the string \"2\" (drop the quotes)");
  EXPECT_EQ(InputErrorMessage([&] { m.GetInt("corners_x"); }),
            "f.yaml: corners_x: expected an integer, got the string \"11\" (drop the quotes)");
  EXPECT_EQ(InputErrorMessage([&] { m.GetDouble("size"); }),
            "f.yaml: size: expected a number, got the string \"9.5\" (drop the quotes)");
  EXPECT_EQ(InputErrorMessage([&] { m.GetInts("ids"); }),
            "f.yaml: ids: expected integers, got the string \"2\" (drop the quotes)");
  EXPECT_EQ(InputErrorMessage([&] { m.GetBool("double_sided"); }),
            "f.yaml: double_sided: expected true or false, got 'yes'");
  EXPECT_EQ(InputErrorMessage([&] { m.GetBool("b2"); }), "f.yaml: b2: expected true or false, got 'off'");
  EXPECT_EQ(InputErrorMessage([&] { m.GetBool("b3"); }), "f.yaml: b3: expected true or false, got 'true'");
  EXPECT_EQ(m.GetInt("n"), 2);
  EXPECT_EQ(m.GetDouble("x"), 9.5);
  EXPECT_TRUE(m.GetBool("t"));
  EXPECT_FALSE(m.GetBool("f"));
  EXPECT_EQ(m.GetString("name"), "12");  // a string may look like a number
}

// yaml-cpp's Load reads the first document alone: a rig or target file's
// keys after a `---` were never read nor checked. Refused, naming the line;
// a lone trailing `---` (an empty document) passes.
TEST(YamlMap, ASecondYamlDocumentIsRefusedNamingItsLine) {
  try {
    YamlMap::LoadString("version: 2\n---\nbogus_key: 1\n", "rig.yaml");
    ADD_FAILURE() << "a second document was read past";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "rig.yaml: line 3: a second YAML document (after `---`): the file is one mapping; remove the "
                 "`---`, or merge its keys into the first document");
  }
  EXPECT_NO_THROW(YamlMap::LoadString("version: 2\n---\n", "rig.yaml"));
  EXPECT_NO_THROW(YamlMap::LoadString("---\nversion: 2\n", "rig.yaml"));
  EXPECT_NO_THROW(YamlMap::LoadString("", "rig.yaml"));  // an empty file: a mapping with no keys
}

// A misspelt required key is missing under its right name, and Finish(),
// which would name the misspelling, is never reached: the message named
// the key the reader wanted alone. A key of the map not read so far and a
// slip or two of typing from the missing one (a letter left out, two
// swapped, the case) is named; one further off is not (it may be a key
// read later: `left`, `right` below), nor one read already.
TEST(YamlMap, AMissingKeyNamesAKeyOfTheMapThatIsAMisspellingOfIt) {
  YamlMap m = YamlMap::LoadString("name: a\nleft: 0\nright: 1\nright_from_lef: 2\n", "f.yaml");
  m.GetString("name");
  m.GetInt("left");
  m.GetInt("right");
  EXPECT_EQ(InputErrorMessage([&] { m.GetDouble("right_from_left"); }),
            "f.yaml: right_from_left: missing key (this map has right_from_lef instead: a typo?)");
  EXPECT_EQ(InputErrorMessage([&] { m.GetInt("rihgt"); }), "f.yaml: rihgt: missing key");  // right is read

  YamlMap first = YamlMap::LoadString("nam: a\nleft: 0\nright: 1\n", "f.yaml");
  EXPECT_EQ(InputErrorMessage([&] { first.GetString("name"); }),
            "f.yaml: name: missing key (this map has nam instead: a typo?)");
  YamlMap swapped = YamlMap::LoadString("fromat: x\nUnits: mm\n", "f.yaml");
  EXPECT_EQ(InputErrorMessage([&] { swapped.GetString("format"); }),
            "f.yaml: format: missing key (this map has fromat instead: a typo?)");
  EXPECT_EQ(InputErrorMessage([&] { swapped.GetString("units"); }),
            "f.yaml: units: missing key (this map has Units instead: a typo?)");

  // A sibling key (another axis, another index) is not named: the reader
  // reads it too, under its own name.
  YamlMap sibling = YamlMap::LoadString("corners_y: 8\nfx: 1000\ncam1: 0\ncorners_z: 1\n", "t.yaml");
  EXPECT_EQ(InputErrorMessage([&] { sibling.GetInt("corners_x"); }), "t.yaml: corners_x: missing key");
  EXPECT_EQ(InputErrorMessage([&] { sibling.GetDouble("fy"); }), "t.yaml: fy: missing key");
  EXPECT_EQ(InputErrorMessage([&] { sibling.GetInt("cam0"); }), "t.yaml: cam0: missing key");
  EXPECT_EQ(InputErrorMessage([&] { sibling.GetInt("corner_y"); }),
            "t.yaml: corner_y: missing key (this map has corners_y instead: a typo?)");

  YamlMap far = YamlMap::LoadString("baseline: 90\nrfl: 1\n", "f.yaml");
  EXPECT_EQ(InputErrorMessage([&] { far.GetDouble("right_from_left"); }), "f.yaml: right_from_left: missing key");
  EXPECT_EQ(InputErrorMessage([&] { far.Finish(); }), "f.yaml: baseline: unknown key");
  // In a nested mapping, as every reader's: the path and the misspelling.
  YamlMap nested = YamlMap::LoadString("modules:\n  - {name: m, right_from_lef: 1}\n", "rig.yaml");
  YamlMap module = nested.GetMaps("modules")[0];
  module.GetString("name");
  EXPECT_EQ(InputErrorMessage([&] { module.GetNode("right_from_left"); }),
            "rig.yaml: modules[0].right_from_left: missing key (this map has right_from_lef instead: a typo?)");
}

TEST(YamlMap, FinishRejectsKeysNobodyRead) {
  YamlMap m = YamlMap::LoadString("known: 1\ntypo_key: 2\n", "f.yaml");
  m.GetInt("known");
  EXPECT_EQ(InputErrorMessage([&] { m.Finish(); }), "f.yaml: typo_key: unknown key");
  m.GetInt("typo_key");
  EXPECT_NO_THROW(m.Finish());
}

TEST(YamlMap, DefaultsCountAsRead) {
  YamlMap m = YamlMap::LoadString("x: 2\n", "f.yaml");
  EXPECT_EQ(m.GetDouble("y", 5.0), 5.0);
  EXPECT_EQ(m.GetInt("x", 3), 2);
  EXPECT_NO_THROW(m.Finish());
}

TEST(YamlMap, ReadKeepsTheDefaultOfAnAbsentKeyAndNamesABadOne) {
  YamlMap m = YamlMap::LoadString("n: 7\nx: 2.5\nflag: false\nbad_int: 1.5\nbad_bool: maybe\n", "f.yaml");
  int n = 1, absent_int = 4;
  double x = 0.5, absent_double = 9.25;
  bool flag = true, absent_bool = true;
  m.Read("n", &n);
  m.Read("x", &x);
  m.Read("flag", &flag);
  m.Read("no_int", &absent_int);
  m.Read("no_double", &absent_double);
  m.Read("no_bool", &absent_bool);
  EXPECT_EQ(n, 7);
  EXPECT_EQ(x, 2.5);
  EXPECT_FALSE(flag);
  EXPECT_EQ(absent_int, 4);
  EXPECT_EQ(absent_double, 9.25);
  EXPECT_TRUE(absent_bool);
  int bad_int = 3;
  bool bad_bool = true;
  EXPECT_EQ(InputErrorMessage([&] { m.Read("bad_int", &bad_int); }), "f.yaml: bad_int: expected an integer");
  EXPECT_EQ(InputErrorMessage([&] { m.Read("bad_bool", &bad_bool); }),
            "f.yaml: bad_bool: expected true or false, got 'maybe'");
  EXPECT_EQ(bad_int, 3);  // a value that does not parse leaves the field as it was
  EXPECT_TRUE(bad_bool);
  EXPECT_NO_THROW(m.Finish());  // the file's keys were all read, the two bad ones included
}

// An options file with every key commented out means "the defaults" (it
// was refused as "expected a YAML mapping at the top level"); a file that
// needs keys then names the first one missing.
TEST(YamlMap, AnEmptyOrCommentOnlyDocumentHasNoKeys) {
  for (const char* text : {"", "# a: 1\n# b: 2\n", "---\n"}) {
    YamlMap m = YamlMap::LoadString(text, "f.yaml");
    EXPECT_FALSE(m.Has("a")) << text;
    EXPECT_EQ(m.GetInt("a", 7), 7) << text;
    EXPECT_EQ(InputErrorMessage([&] { m.GetInt("b"); }), "f.yaml: b: missing key") << text;
    EXPECT_NO_THROW(m.Finish()) << text;
  }
}

// yaml-cpp keeps a repeated key's first value silently ("units: mm" then
// "units: m" read as mm); a strict reader names the key, at any depth.
TEST(YamlMap, AKeyGivenTwiceIsRefused) {
  EXPECT_EQ(InputErrorMessage([] { YamlMap::LoadString("units: mm\nunits: m\n", "f.yaml"); }),
            "f.yaml: units: given twice in one mapping: keep one");
  YamlMap m = YamlMap::LoadString("match: {p1: 8, p1: 9}\nother: {p1: 1}\n", "f.yaml");
  EXPECT_EQ(InputErrorMessage([&] { m.GetMap("match"); }), "f.yaml: match.p1: given twice in one mapping: keep one");
  EXPECT_EQ(m.GetMap("other").GetInt("p1"), 1);  // one per mapping is fine
  EXPECT_EQ(InputErrorMessage([] { YamlMap::LoadString("? [a, b]\n: 1\n", "f.yaml"); }),
            "f.yaml: line 1: a key must be a plain name, not a list");
  // Unquoted, null and ~ are YAML's null: the message said only "plain
  // name" of a key that looks like one.
  EXPECT_EQ(InputErrorMessage([] { YamlMap::LoadString("a: 1\nnull: 3\n", "f.yaml"); }),
            "f.yaml: line 2: a key must be a plain name, not null (write \"null\" for a key of that name)");
  EXPECT_EQ(InputErrorMessage([] { YamlMap::LoadString("match: {~: 3}\n", "f.yaml").GetMap("match"); }),
            "f.yaml: match: line 1: a key must be a plain name, not null (write \"null\" for a key of that name)");
  EXPECT_EQ(InputErrorMessage([] { YamlMap::LoadString("{a: 1}: 2\n", "f.yaml"); }),
            "f.yaml: line 1: a key must be a plain name, not a mapping");
  EXPECT_EQ(YamlMap::LoadString("\"null\": 3\n", "f.yaml").GetInt("null"), 3);  // quoted: a name
}

// A pipe reads as a file (`--options <(printf ...)`, /dev/stdin): the
// shell's process substitution was refused as "not a regular file". A
// device is still refused.
TEST(YamlMap, APipeIsReadLikeAFile) {
  const std::string fifo = ::testing::TempDir() + "/yaml_pipe";
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo) << "match: {p1: 7}\n"; });  // blocks until the reader opens it
  std::optional<YamlMap> m;
  std::string refused;
  try {
    m = YamlMap::LoadFile(fifo);
  } catch (const InputError& e) {
    refused = e.what();
    std::ifstream release(fifo);  // the writer waits for a reader: let it finish
  }
  writer.join();
  ASSERT_TRUE(m) << refused;
  EXPECT_EQ(m->GetMap("match").GetInt("p1"), 7);
  std::filesystem::remove(fifo);
  EXPECT_EQ(InputErrorMessage([] { YamlMap::LoadFile("/dev/null"); }), "/dev/null: is not a regular file");
}

TEST(YamlMap, SyntaxErrorsAreInputErrors) {
  EXPECT_THROW(YamlMap::LoadString("a: [1, 2\n", "f.yaml"), InputError);
  EXPECT_THROW(YamlMap::LoadString("- just a list\n", "f.yaml"), InputError);
  EXPECT_THROW(YamlMap::LoadFile("/nonexistent/f.yaml"), InputError);
}

// A section with every key commented out is YAML's null, not a mapping:
// GetMapOrEmpty (the options file's sections) reads it, and `~`, as a
// mapping with no keys; GetMap (the rig file, target file and the others,
// whose sections are required) still refuses it, as both refuse a scalar.
TEST(YamlMap, AnEmptySectionIsAMappingOnlyWhereAskedFor) {
  YamlMap y = YamlMap::LoadString("a:\n#  k: 1\nb: ~\nc: 3\n", "f.yaml");
  YamlMap a = y.GetMapOrEmpty("a");
  EXPECT_TRUE(a.Keys().empty());
  EXPECT_EQ(a.GetInt("k", 5), 5);
  EXPECT_NO_THROW(a.Finish());
  EXPECT_EQ(a.Where("k"), "f.yaml: a.k");
  EXPECT_TRUE(y.GetMapOrEmpty("b").Keys().empty());
  EXPECT_EQ(InputErrorMessage([&] { y.GetMapOrEmpty("c"); }), "f.yaml: c: expected a mapping");
  EXPECT_NO_THROW(y.Finish());
}

TEST(YamlMap, GetMapStillRefusesAnEmptySection) {
  YamlMap y = YamlMap::LoadString("cameras:\n#  - name: cam0\ntarget: ~\n", "rig.yaml");
  EXPECT_EQ(InputErrorMessage([&] { y.GetMap("cameras"); }), "rig.yaml: cameras: expected a mapping");
  EXPECT_EQ(InputErrorMessage([&] { y.GetMap("target"); }), "rig.yaml: target: expected a mapping");
}

}  // namespace
}  // namespace stereorig
