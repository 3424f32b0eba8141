// A small, fast, portable random generator for the simulator. Every image
// draws from its own stream, seeded from (dataset seed, what it is), so the
// bytes do not depend on thread scheduling, library version or platform
// (std::normal_distribution's algorithm is implementation-defined).
#pragma once

#include <cmath>
#include <cstdint>
#include <initializer_list>

namespace stereorig {

// splitmix64: a bijective mix with good avalanche; Vigna (2015).
inline uint64_t Mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A stream key from several integers (seed, kind, capture, camera, ...).
inline uint64_t StreamKey(std::initializer_list<uint64_t> parts) {
  uint64_t h = 0x2545f4914f6cdd1dULL;
  for (uint64_t p : parts) h = Mix64(h ^ Mix64(p));
  return h;
}

class Rng {
 public:
  explicit Rng(uint64_t key) : state_(key) {}
  uint64_t Next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Standard normal: Marsaglia's polar method (no trigonometry; both values used).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * Uniform() - 1.0;
      v = 2.0 * Uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double k = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * k;
    has_spare_ = true;
    return u * k;
  }

 private:
  uint64_t state_;
  bool has_spare_ = false;
  double spare_ = 0;
};

}  // namespace stereorig
