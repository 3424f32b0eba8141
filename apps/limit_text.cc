#include "apps/limit_text.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "calib/core/number_text.h"

namespace stereorig {

namespace {

constexpr int kMostDecimals = 17;  // past this a double's decimals are noise

int Compare(double a, double b) { return a < b ? -1 : a > b ? 1 : 0; }

}  // namespace

std::string FixedText(double value, int decimals) {
  char text[400];  // %.17f of the largest double: 309 digits, the point and 17 decimals
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  std::string s = text;
  // A negative number whose digits are all zeros is a zero: drop the sign.
  if (s[0] == '-' && s.find_first_not_of("0.", 1) == std::string::npos) s.erase(0, 1);
  return s;
}

int LimitDecimals(double limit, int least) {
  for (int d = least; d < kMostDecimals; ++d)
    if (std::strtod(FixedText(limit, d).c_str(), nullptr) == limit) return d;
  return kMostDecimals;
}

std::string LimitText(double limit, int least) {
  const int d = LimitDecimals(limit, least);
  if (d >= kMostDecimals) return ShortestNumberText(limit);  // below 1e-17 or the like: no plain decimal holds it
  return FixedText(limit, d);
}

std::string ValueBesideLimitText(double value, double limit, int least) {
  const int order = Compare(std::abs(value), limit);
  for (int d = LimitDecimals(limit, least); d <= kMostDecimals; ++d) {
    const std::string text = FixedText(value, d);
    if (Compare(std::abs(std::strtod(text.c_str(), nullptr)), limit) == order) return text;
  }
  return ShortestNumberText(value);  // reads back as value itself: orders as it does
}

}  // namespace stereorig
