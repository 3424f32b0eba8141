#include "calib/core/number_text.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

namespace stereorig {
namespace {

TEST(NumberText, ShortestTextIsShortAndReadsBackToTheSameDouble) {
  EXPECT_EQ(ShortestNumberText(0.6), "0.6");
  EXPECT_EQ(ShortestNumberText(0.1 + 0.2), "0.30000000000000004");  // not 0.3: that is another double
  EXPECT_EQ(ShortestNumberText(100000), "100000");
  EXPECT_EQ(ShortestNumberText(-0.0001), "-0.0001");
  EXPECT_EQ(ShortestNumberText(0), "0");
  EXPECT_EQ(ShortestNumberText(1e-7), "1e-07");
  EXPECT_EQ(ShortestNumberText(1e20), "1e+20");
  for (const double x : {0.6, 1024.9829461621528, -0.089999999999999997, 0.00020000000000000001, 1e-5, 9.99e14, 1e15,
                         std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                         -std::numeric_limits<double>::denorm_min()})
    EXPECT_EQ(std::strtod(ShortestNumberText(x).c_str(), nullptr), x) << ShortestNumberText(x);
}

}  // namespace
}  // namespace stereorig
