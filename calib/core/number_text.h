// A number as text for messages and files: printf's %g to a number of
// significant digits (17 round-trips a double), or the shortest text that
// round-trips, for files people edit (rig_file.h's FormatDouble).
#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

namespace stereorig {

inline std::string NumberText(double x, int significant_digits = 6) {
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", significant_digits, x);
  return text;
}

// The shortest text that reads back (strtod, yaml-cpp) as the same double:
// 0.6 where %.17g writes 0.59999999999999998. Plain decimals for magnitudes
// in [1e-5, 1e15), where they stay short (100000, not to_chars' shortest
// 1e+05); exponent form outside it (1e-07, 1e+20), and nan, inf as to_chars.
inline std::string ShortestNumberText(double x) {
  char text[64];  // fixed below 1e15: at most 16 digits, a sign and a point, and 5 + 17 decimals
  const double magnitude = std::abs(x);
  const bool plain = magnitude == 0 || (magnitude >= 1e-5 && magnitude < 1e15);
  const std::to_chars_result r = plain ? std::to_chars(text, text + sizeof text, x, std::chars_format::fixed)
                                       : std::to_chars(text, text + sizeof text, x);
  return std::string(text, r.ptr);
}

}  // namespace stereorig
