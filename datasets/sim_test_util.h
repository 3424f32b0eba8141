// Test helpers: small, fast specs (tests only; not part of the library).
#pragma once

#include <cmath>
#include <string>

#include "datasets/sim_spec.h"

namespace stereorig {

// The default camera scaled down by `factor` (e.g. 4: 188x146 px): the same
// field of view and distortion, 1/factor^2 of the pixels.
inline CameraSpec ScaledCamera(const CameraSpec& c, int factor) {
  CameraSpec s = c;
  s.width_px = (c.width_px + factor - 1) / factor;
  s.height_px = (c.height_px + factor - 1) / factor;
  s.intrinsics[0] /= factor;
  s.intrinsics[1] /= factor;
  s.intrinsics[2] = (c.intrinsics[2] + 0.5) / factor - 0.5;
  s.intrinsics[3] = (c.intrinsics[3] + 0.5) / factor - 0.5;
  return s;
}

// M modules on a circle of radius 200 mm around the origin (M = 2: the
// default's facing pair), small cameras, few captures.
inline SimSpec SmallRingSpec(int modules, int factor, int captures) {
  const SimSpec d = DefaultSimSpec();
  SimSpec s = d;
  s.modules.clear();
  for (int m = 0; m < modules; ++m) {
    ModuleSpec ms = d.modules[m % 2];
    ms.name = "module" + std::to_string(m);
    const double a = 2 * M_PI * m / modules;
    ms.center_mm = Eigen::Vector3d(200 * std::sin(a), 0, -200 * std::cos(a));
    ms.left = ScaledCamera(ms.left, factor);
    ms.right = ScaledCamera(ms.right, factor);
    ms.projector.line_sigma_mrad *= factor;  // keep the lines about a pixel wide
    ms.projector.lines = (ms.projector.lines - 1) / factor + 1;
    s.modules.push_back(ms);
  }
  s.calibration.captures = captures;
  s.calibration.min_corners_per_camera = modules > 2 ? 0 : 4;
  return s;
}

}  // namespace stereorig
