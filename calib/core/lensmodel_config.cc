#include "lensmodel_config.h"

#include <climits>
#include <cstdint>

#include "mrcal_c.h"

namespace stereorig {

std::string LensmodelConfigProblem(const std::string& lensmodel_name) {
  mrcal_lensmodel_t m;
  if (!mrcal_lensmodel_from_name(&m, lensmodel_name.c_str()) || m.type != MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC)
    return "";
  const mrcal_LENSMODEL_SPLINED_STEREOGRAPHIC__config_t& c = m.LENSMODEL_SPLINED_STEREOGRAPHIC__config;
  const std::string where = "'" + lensmodel_name + "': ";
  // mrcal reads each number into 16 bits without a range check: Nx=-4 read
  // as 65532, Nx=65536 as 0. Its own spelling of what it read differs from
  // the name given then.
  char canonical[256] = "";
  if (!mrcal_lensmodel_name(canonical, sizeof canonical, &m) || lensmodel_name != canonical)
    return where + "mrcal reads it as '" + canonical +
           "': order, Nx, Ny and fov_x_deg are whole numbers from 0 to 65535, written plainly";
  // mrcal's knot spacing (mrcal.c, _mrcal_precompute_lensmodel_data): a
  // quadratic spline needs one knot interval past the field's edge, a cubic
  // two; the grid must hold them and an interval inside.
  if (c.order != 2 && c.order != 3)
    return where + "order=" + std::to_string(c.order) + ": mrcal's splines are of order 2 or 3";
  const int min_knots = c.order == 2 ? 3 : 4;
  if (c.Nx < min_knots || c.Ny < min_knots)
    return where + "Nx=" + std::to_string(c.Nx) + " Ny=" + std::to_string(c.Ny) + ": an order " +
           std::to_string(c.order) + " spline needs Nx and Ny >= " + std::to_string(min_knots) + " (mrcal's minimum)";
  // mrcal counts a model's intrinsics, 2 per knot and the 4 of the core,
  // in an int: a larger grid wraps (65535 x 32769 knots count 4 + 2 x
  // 2147450415 = 4295032834, read as 65538 in 32 bits: a rig file giving
  // 65538 intrinsics would pass the count, then abort in mrcal).
  const std::int64_t num_intrinsics = 4 + 2 * static_cast<std::int64_t>(c.Nx) * c.Ny;
  if (num_intrinsics > INT_MAX)
    return where + "Nx=" + std::to_string(c.Nx) + " Ny=" + std::to_string(c.Ny) + ": " +
           std::to_string(num_intrinsics) + " intrinsics, more than mrcal counts (" + std::to_string(INT_MAX) + ")";
  // The spline spans the stereographic projection u = 2 tan(theta / 2) out
  // to theta = fov_x_deg / 2 off the axis: 0 spans nothing, and u grows
  // without bound as theta reaches 180 deg (fov_x_deg 360), past which
  // tan turns negative.
  if (c.fov_x_deg <= 0 || c.fov_x_deg >= 360)
    return where + "fov_x_deg=" + std::to_string(c.fov_x_deg) +
           ": must be in (0, 360), the horizontal field of view the stereographic projection can span, deg";
  return "";
}

}  // namespace stereorig
