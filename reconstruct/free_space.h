// The free-space (visibility) test across modules: a module's point is refuted
// when the other modules measured a surface facing that module's left camera
// in front of it, along the camera's own ray. The camera could not have seen
// the point through that surface, so one of the two is wrong; the facing
// surface, measured by another module from another direction, is kept.
//
// Why: where a module's right camera grazes a surface (1 - dd/dx < 0.3), the
// matcher can keep a whole patch matched tens of px off, a smooth surface
// behind the real one inside the measurement volume; nothing in that
// module's own data tells it from a surface ("The oblique plate (session
// 22)" (reconstruct-log.md)). Another module that measures the real surface
// puts its points in front of that patch along the first module's rays.
//
// Per module j: a depth buffer over module j's rectified left image holds,
// at each pixel, the largest disparity (in module j's image-disparity units,
// rectify.h: the nearest) of the other modules' points that project there
// and face camera j (unit normal . unit direction to camera j >
// min_facing_cos). A point P of module j at pixel (u, v) with disparity d_P
// is refuted when at least `min_support` of the buffer's pixels (x, y)
// within `window_radius_px` of (u, v) hold a disparity > d_P(x, y) +
// margin_px, where d_P(x, y) is P's own surface (the plane through P normal
// to its normal) at that pixel: on a surface camera j sees obliquely the
// disparity steps by up to B / Z tan(75 deg) ~ 1.7 px per px, and a correct
// neighbour two px away would otherwise read nearer by more than the margin.
//
// Comparing disparities is comparing depths scaled by the module's own
// noise: Z = f B / (d + offset), so a margin of m px is m sigma_Z / sigma_d
// with sigma_Z = Z^2 sigma_d / (f B) the depth sigma of a point whose
// disparity scatters by sigma_d (docs/reconstruct.md, the option's row).
// The rule never removes a point behind the facing surface (a facing
// module's correct points, seen from its partner, lie behind the partner's
// surface); a point no other module's point hides goes only with its whole
// surface (below).
//
// Whole surfaces. A wrong patch is refuted only where another module's
// cover lies in front of it; its points beyond that cover survive (the
// ring's plate at seed 11: 84 of module 2's 2 587 wrong points, "The
// free-space test across modules, whole surfaces (session 23)",
// reconstruct-log.md). So the points are first grouped into surfaces, per
// module: points joined through neighbouring pixels of its rectified left
// image whose points lie within surface_max_edge_mm of each other (the
// mesh's own rule for a depth jump). A surface at least surface_fraction of
// whose points the first pass refutes is wrong as a whole: all of it goes,
// and the points the first pass refuted elsewhere are tested again with
// depth buffers without the wrong surfaces, which so refute nothing more.
// The shares are read once: two surfaces each hidden mostly by the other
// both go.
//
// The hiding point in the refuted module's own images (the second pass). A
// point of a correct surface can still be refuted by another module's
// points a little off their surface: seen from a camera that views the
// surface obliquely, a ~1 mm offset along the normal is several times the
// margin along the ray (the ring's plate at seed 5: module 2's points
// 0.97-1.13 mm off took 1 303 of module 1's points, which module 1's left
// camera sees ~75 deg off the plate's normal). Had the hiding surface
// really been there, module j's own cameras would have seen it: in the
// second pass a nearer buffer pixel counts only where module j's rectified
// pair correlates there (the best ZNCC of the sub-pixel window, linear
// taps, warped by the hiding point's own plane in j's image, at that
// plane's disparity at the pixel's centre and 0.5 px either side, >=
// min_zncc: a correlation j's matcher would have started from; no fit, no
// distinctness test), or where the pair cannot tell: j's right camera grazes
// that plane (1 - dd/dx < 0.3), or no window can be read (off the image,
// flat or blank). Not in the first pass: a module whose view of the surface
// is poor (seed 5's module 2, 1 - dd/dx in [0.3, 0.5)) correlates little of
// it even where it is there, and its wrong patch must still be found: with
// the check there, seed 5's module 2 kept wrong surfaces (std 0.29 -> 0.82
// mm).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "calib/core/pose.h"
#include "reconstruct/point_cloud.h"
#include "reconstruct/rectify.h"
#include "reconstruct/subpixel_refine.h"

namespace stereorig {

struct FreeSpaceOptions {
  double margin_px = 4.0;         // in front by more than this (the tested module's disparity); default 4 px
  int window_radius_px = 2;       // buffer pixels searched around the point's pixel; default 2 (5x5)
  int min_support = 3;            // buffer pixels in front needed; default 3
  double min_facing_cos = 0.26;   // another module's point faces the camera if n.v exceeds this (~75 deg); default 0.26
  double surface_fraction = 0.8;  // a surface this share of which is refuted goes whole; (0, 1], default 0.8
  // Not keys of their own: Runtime::Process sets these from the runtime's
  // options, over whatever RuntimeOptions::free_space holds.
  // Neighbouring pixels' points within this distance are one surface: the
  // mesh's mesh_max_edge_mm. Default 1.5.
  double surface_max_edge_mm = 1.5;
  // The second pass's photo check (FreeSpaceView's images): the window and
  // the least ZNCC, the matcher's (match.subpixel_half_width_px /
  // _height_px, match.min_zncc).
  SubpixelOptions window;
  double min_zncc = 0.8;
};

// One module's rectified left camera, as the runtime's plan holds it.
struct FreeSpaceView {
  RectifiedGeometry geometry;                                            // module j's rectification (rectify.h)
  Pose module_from_reference;                                            // S[j][0]
  Eigen::Vector3d camera_centre_reference_mm = Eigen::Vector3d::Zero();  // its left camera centre
  // Its rectified pair (CV_8UC1, geometry.size) for the second pass's photo
  // check; empty: no check (every nearer buffer pixel counts).
  cv::Mat left_rectified, right_rectified;
};

// What the test says of a point.
enum class FreeSpaceVerdict : uint8_t {
  kKept = 0,
  kSeenThrough = 1,           // other modules' facing points hide it from its camera
  kOnSeenThroughSurface = 2,  // nothing hides it, but it lies on a surface mostly seen through: removed whole
};

// clouds[j]: module j's points (reference frame, mm) with unit normals; the
// cloud's `module` field is ignored (clouds[j] is module j's). Returns, per
// module, one FreeSpaceVerdict per point (as uint8_t: 0 = kept).
// views.size() == clouds.size().
std::vector<std::vector<uint8_t>> FreeSpaceRefuted(const std::vector<FreeSpaceView>& views,
                                                   const std::vector<PointCloud>& clouds,
                                                   const FreeSpaceOptions& options);

}  // namespace stereorig
