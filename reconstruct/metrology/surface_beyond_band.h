// A part of the artifact measured beyond the capture band (vdi2634.h). The
// band decides which points are the artifact's; a patch measured further off
// than the band (one grid period is ~3.5 mm deep at 200 mm and deeper
// further away) then fell out of the figures, and a larger gross error
// passed where a smaller one failed. Clutter lies beyond the band too (a
// mount, a stand, the table), so a point beyond it is not the artifact's
// for being near. What tells them apart is where they lie: a part of the
// artifact measured off takes the place of its surface, so its points lie
// in directions where the artifact's own surface is missing while the
// directions around are measured; a mount or a stand lies where the
// artifact is hidden, so the directions around it are not measured either
// (the artifact's far side, below it). A thin layer over cells that hold
// the surface too, at least half as dense as a typical cell of surface and
// facing as the surface there does (its points' normals), is one module's
// part measured off where another module holds it (their overlap); a table
// under a sphere lies in such cells too, but faces up, not out of the
// sphere. Without normals nothing tells them apart, and a layer over the
// surface is not judged a part (no false alarm; an overlap's patch then
// passes unseen). A part is one continuous layer of at least 20 points (a
// few false matches are not).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "reconstruct/metrology/plate_outline.h"

namespace stereorig {

struct SurfaceBeyondBand {
  int points = 0;                          // beyond the band, where the surface is missing among measured directions
  double nearest_mm = 0, farthest_mm = 0;  // their distance to the shape's surface
  // Each part's mean signed offset (a plate's: along its normal): parts may
  // lie on either side (a clamp in front of a plate, a patch behind it).
  std::vector<double> part_mean_off_mm;
  bool found() const { return points > 0; }
};

// Points within [band_mm, kBeyondBandWidths * band_mm] of a sphere's surface
// (centre, radius; inside or outside it) in directions from its centre
// where the band holds no surface, those directions surrounded by ones that
// do. normals: parallel to pts, or empty (a cloud without nx ny nz); where
// given, only points facing out of the sphere count (a part measured off
// keeps the surface's orientation). axis / cos_cone: directions within the
// cone about that unit axis are ignored (a ball bar's shaft; cos_cone > 1:
// none). Three bands (15 mm by default): a grid period's depth grows with
// the distance, ~3.5 mm at 200 mm, and a patch a period or two off must
// still be seen.
inline constexpr double kBeyondBandWidths = 3;
SurfaceBeyondBand SphereSurfaceBeyondBand(const std::vector<Eigen::Vector3d>& pts,
                                          const std::vector<Eigen::Vector3d>& normals, const Eigen::Vector3d& center_mm,
                                          double radius_mm, double band_mm,
                                          const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ(), double cos_cone = 2);

// Points within [band_mm, kBeyondBandWidths * band_mm] of a plate's plane
// (unit normal, offset: normal . p = offset_mm; either side) inside its
// outline eroded by margin_mm (where F is evaluated), where the band holds
// no face, surrounded by cells that do. A thin plate's far face lies beyond
// the band where the face is not seen: points whose normals (parallel to
// pts, or empty) face away from face_side (+1 or -1 along `normal`, the
// side the face was measured from; 0: unknown) are left out as it.
SurfaceBeyondBand PlateSurfaceBeyondBand(const std::vector<Eigen::Vector3d>& pts,
                                         const std::vector<Eigen::Vector3d>& normals, const Eigen::Vector3d& normal,
                                         double offset_mm, int face_side, const PlaneOutline& outline, double margin_mm,
                                         double band_mm);

}  // namespace stereorig
