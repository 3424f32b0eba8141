// Wall time since a steady_clock point, in milliseconds: the unit of every
// step time in the reconstruction reports and the bench.
#pragma once

#include <chrono>

namespace stereorig {

inline double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace stereorig
