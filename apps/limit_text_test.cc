#include "apps/limit_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

namespace stereorig {
namespace {

// The limit as the certificate gives it, no fewer decimals than the table's 4.
TEST(LimitText, TheLimitIsPrintedAsGiven) {
  EXPECT_EQ(LimitText(0.34152), "0.34152");
  EXPECT_EQ(LimitText(1.5), "1.5000");
  EXPECT_EQ(LimitText(0.3), "0.3000");
  EXPECT_EQ(LimitText(0.123456789), "0.123456789");
  EXPECT_EQ(LimitText(0.1 + 0.2), "0.30000000000000004");  // another double than 0.3, said so
}

// P_F 0.341527 against 0.34152 printed "0.3415 (MPE 0.3415) FAIL" with 4
// decimals: now the value has as many as the limit, and more where that
// still ties.
TEST(LimitText, AValueOverItsLimitNeverPrintsEqual) {
  EXPECT_EQ(ValueBesideLimitText(0.341527, 0.34152), "0.34153");
  EXPECT_EQ(ValueBesideLimitText(0.3415201, 0.34152), "0.3415201");
  EXPECT_EQ(ValueBesideLimitText(0.3415199, 0.34152), "0.3415199");  // under it: not printed equal either
  EXPECT_EQ(ValueBesideLimitText(0.34152, 0.34152), "0.34152");      // equal: equal (and passes)
  EXPECT_EQ(ValueBesideLimitText(0.2, 1.5), "0.2000");               // far from it: the table's 4 decimals
  EXPECT_EQ(ValueBesideLimitText(-1.50004, 1.5), "-1.50004");        // |P_S| over the MPE
  EXPECT_EQ(ValueBesideLimitText(-1.49996, 1.5), "-1.49996");
  // The next double above the limit: only its full text tells them apart.
  const double next = std::nextafter(0.34152, 1.0);
  EXPECT_GT(std::strtod(ValueBesideLimitText(next, 0.34152).c_str(), nullptr), 0.34152);
}

TEST(LimitText, NoNegativeZero) {
  EXPECT_EQ(FixedText(-0.00001, 4), "0.0000");
  EXPECT_EQ(FixedText(-0.0, 4), "0.0000");
  EXPECT_EQ(FixedText(-0.00006, 4), "-0.0001");
  EXPECT_EQ(ValueBesideLimitText(-0.00001, 1.5), "0.0000");
}

}  // namespace
}  // namespace stereorig
