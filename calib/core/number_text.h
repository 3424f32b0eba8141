// A number as text for messages and files: printf's %g to a number of
// significant digits (17 round-trips a double; rig_file.h's FormatDouble).
#pragma once

#include <cstdio>
#include <string>

namespace stereorig {

inline std::string NumberText(double x, int significant_digits = 6) {
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", significant_digits, x);
  return text;
}

}  // namespace stereorig
