#include "apps/cli_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace stereorig {
namespace {

// What a terminal is handed of an error line: well-formed UTF-8 as it is,
// every other byte as \xNN. The well-formed sequences are those of
// RFC 3629's table (section 4): the first continuation byte's range
// depends on the lead byte.
TEST(PrintableText, KeepsWellFormedUtf8) {
  for (const std::string s : {"plain ascii", "k\xC3\xA5sa", "\xC2\xA0", "\xE0\xA0\x80", "\xE2\x82\xAC", "\xED\x9F\xBF",
                              "\xEF\xBF\xBD", "\xF0\x90\x80\x80", "\xF4\x8F\xBF\xBF"})
    EXPECT_EQ(PrintableText(s), s) << s;
}

// A printed command line pasted into a shell gives each path as one
// argument: a plain path as it is, one with a space, a quote or another
// character the shell reads in single quotes (each ' closed, escaped, reopened).
TEST(ShellQuoted, QuotesOnlyWhatTheShellWouldSplitOrExpand) {
  EXPECT_EQ(ShellQuoted("/tmp/rect/module0_left.png"), "/tmp/rect/module0_left.png");
  EXPECT_EQ(ShellQuoted("sp ace/m.png"), "'sp ace/m.png'");
  EXPECT_EQ(ShellQuoted("it's"), "'it'\\''s'");
  EXPECT_EQ(ShellQuoted(""), "''");
  EXPECT_EQ(ShellQuoted("$HOME*"), "'$HOME*'");
}

TEST(PrintableText, EscapesControlBytes) {
  EXPECT_EQ(PrintableText("a\x1B[2Jb\x7F"), "a\\x1B[2Jb\\x7F");
  EXPECT_EQ(PrintableText("\xC2\x9B"), "\\xC2\\x9B");  // U+009B, CSI: a C1 control
}

// Forms a strict decoder refuses: each byte written as \xNN, so that the
// line shows what the file held rather than a character it never meant.
TEST(PrintableText, EscapesIllFormedSequencesByteByByte) {
  EXPECT_EQ(PrintableText("\xC0\xAF"), "\\xC0\\xAF");           // overlong '/'
  EXPECT_EQ(PrintableText("\xE0\x80\xAF"), "\\xE0\\x80\\xAF");  // overlong, 3 bytes
  EXPECT_EQ(PrintableText("\xF0\x80\x80\xAF"), "\\xF0\\x80\\x80\\xAF");
  EXPECT_EQ(PrintableText("\xED\xA0\x80"), "\\xED\\xA0\\x80");           // a UTF-16 surrogate
  EXPECT_EQ(PrintableText("\xF4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80");  // past U+10FFFF
  EXPECT_EQ(PrintableText("\xF5\x80\x80\x80"), "\\xF5\\x80\\x80\\x80");
  EXPECT_EQ(PrintableText("\xAB"), "\\xAB");             // a lone continuation byte
  EXPECT_EQ(PrintableText("x\xE2\x82"), "x\\xE2\\x82");  // cut short at the end
  EXPECT_EQ(PrintableText("\xE2\x82x"), "\\xE2\\x82x");  // cut short by a character
}

// A whole-number option takes every int of its range, down to the ends,
// and refuses the numbers just past them by its rule and the value (an int's
// ends: no wrap-around of 2^31 or -2^31 - 1 into range).
TEST(AddWholeNumberOption, TakesItsRangesEndsAndRefusesPastThem) {
  constexpr int kMin = std::numeric_limits<int>::min(), kMax = std::numeric_limits<int>::max();
  auto parse = [](int min, int max, const std::string& text, int* value) -> std::string {
    CLI::App app;
    AddWholeNumberOption(app, "--n", value, min, max, "n");
    std::vector<std::string> args = {"--n", text};
    std::reverse(args.begin(), args.end());  // CLI11 takes a vector in reverse order
    try {
      app.parse(args);
    } catch (const CLI::ParseError& e) {
      return e.what();
    }
    return "";
  };
  int value = 7;
  EXPECT_EQ(parse(kMin, kMax, "-2147483648", &value), "");
  EXPECT_EQ(value, kMin);
  EXPECT_EQ(parse(kMin, kMax, "2147483647", &value), "");
  EXPECT_EQ(value, kMax);
  EXPECT_EQ(parse(kMin, kMax, "2147483648", &value), "--n: must be at most 2147483647, got 2147483648");
  EXPECT_EQ(parse(kMin, kMax, "-2147483649", &value), "--n: must be >= -2147483648, got -2147483649");
  EXPECT_EQ(parse(kMin, kMax, "1.0", &value), "--n: must be a whole number, got 1.0");
  EXPECT_EQ(parse(-4, 4, "-4", &value), "");
  EXPECT_EQ(value, -4);
  EXPECT_EQ(parse(-4, 4, "-5", &value), "--n: must be in [-4, 4], got -5");
  EXPECT_EQ(parse(-4, 4, "18446744073709551617", &value), "--n: must be in [-4, 4], got 18446744073709551617");
  EXPECT_EQ(parse(-4, 4, "- 3", &value), "--n: must be a whole number in [-4, 4], got - 3");
  EXPECT_EQ(value, -4);  // left as it was by each refusal
  EXPECT_EQ(parse(1, kMax, "+3", &value), "");
  EXPECT_EQ(value, 3);
}

}  // namespace
}  // namespace stereorig
