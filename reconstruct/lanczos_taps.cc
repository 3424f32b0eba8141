#include "reconstruct/lanczos_taps.h"

#include <cmath>

namespace stereorig {
namespace {

// Lanczos-3 kernel L(s) = sinc(s) sinc(s/3) and its derivative.
void Lanczos3(double s, double* value, double* slope) {
  if (std::abs(s) < 1e-8) {
    *value = 1.0;
    *slope = 0.0;
    return;
  }
  if (std::abs(s) >= 3.0) {
    *value = *slope = 0.0;
    return;
  }
  const double a = M_PI * s, b = a / 3.0;
  const double sa = std::sin(a), sb = std::sin(b), ca = std::cos(a), cb = std::cos(b);
  const double num = 3.0 * sa * sb, den = a * a;
  *value = num / den;
  const double dnum = 3.0 * M_PI * (ca * sb + sa * cb / 3.0);
  const double dden = 2.0 * M_PI * a;
  *slope = (dnum * den - num * dden) / (den * den);
}

}  // namespace

const LanczosTable& LanczosTapTable() {
  static const LanczosTable table = [] {
    LanczosTable t{};
    for (int i = 0; i <= kLanczosSteps; ++i) {
      const double frac = double(i) / kLanczosSteps;
      double w[6], g[6], sw = 0, sg = 0;
      for (int k = 0; k < 6; ++k) {
        Lanczos3(frac - (k - 2), &w[k], &g[k]);
        sw += w[k];
        sg += g[k];
      }
      for (int k = 0; k < 6; ++k) {
        t[i].w[kLanczosLane0 + k] = float(w[k] / sw);
        t[i].g[kLanczosLane0 + k] = float((g[k] * sw - w[k] * sg) / (sw * sw));
      }
    }
    return t;
  }();
  return table;
}

}  // namespace stereorig
