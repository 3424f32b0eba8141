// Analytic objects for the simulator's scenes: exact ray intersection (closed
// form where one exists, sphere tracing on an exact or bounded distance for
// the torus rim and the bumpy tuber), normals, weak surface texture, dense
// surface samples for ground truth, and a YAML description.
//
// Each object lives in its own frame ("object"), placed in the world by
// world_from_object. Rays are (origin, unit direction) in mm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "calib/core/pose.h"
#include "datasets/sim_spec.h"

namespace stereorig {

// One analytic surface piece, in the object frame.
class Shape {
 public:
  virtual ~Shape() = default;
  // Closest hit with t in (t_min, t_max): sets *t and the outward unit
  // normal *n (object frame). `d` is a unit vector.
  virtual bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                         Eigen::Vector3d* n) const = 0;
  // Samples of the surface, no two neighbours farther apart than `spacing_mm`
  // (object frame), appended to `out`.
  virtual void Sample(double spacing_mm, std::vector<Eigen::Vector3d>* out) const = 0;
};

std::unique_ptr<Shape> MakeSphere(const Eigen::Vector3d& center, double radius);
// Open tube around `axis` (0 = x, 1 = y, 2 = z) through the origin, from lo to hi.
std::unique_ptr<Shape> MakeTube(double radius, double lo, double hi, int axis);
// Annulus r0 <= rho <= r1 in the plane z = z0, normal +z if `up` else -z.
std::unique_ptr<Shape> MakeDisk(double z0, double r0, double r1, bool up);
// Torus around z: major radius R, minor r, centred at z = zc. Sampled on its
// upper half only (the rim of a cup; the lower half is inside the wall).
std::unique_ptr<Shape> MakeRimTorus(double major_mm, double minor_mm, double zc);
// Axis-aligned box centred on the origin.
std::unique_ptr<Shape> MakeBox(const Eigen::Vector3d& half_size_mm);
// A bumpy ellipsoid: |u| = 1 + h(u/|u|) with u = p / semi_axes and h a sum of
// low-frequency sinusoids on the unit sphere, |h| <= bump.
std::unique_ptr<Shape> MakeBumpyEllipsoid(const Eigen::Vector3d& semi_axes_mm, double bump, uint64_t seed);

struct SceneObject {
  int id = 0;                   // object-ID map value (1..255)
  std::string type;             // "sphere", "cup", "box", "tube", "bumpy_ellipsoid"
  std::string description;      // one line for object.yaml
  std::string parameters_yaml;  // "key: value" lines (object.yaml), indented by the writer
  Pose world_from_object;
  Pose object_from_world;
  Eigen::Vector3d bound_center_world = Eigen::Vector3d::Zero();
  double bound_radius_mm = 0;
  double albedo = 0.8;
  // Weak texture: albedo * (1 + contrast * T(p_object)), T in [-1, 1].
  double texture_contrast = 0;
  Eigen::Vector3d texture_k[4];  // spatial frequency vectors (rad/mm)
  double texture_phase[4] = {0, 0, 0, 0};
  std::vector<std::unique_ptr<Shape>> shapes;
  // Ground-truth sampling drops samples that lie inside the solid of another
  // part of the same object (the ball bar's rod inside its balls, the cup's
  // walls inside its rim bead). Object frame. May be empty.
  std::function<bool(const Eigen::Vector3d&)> inside_solid;

  double Albedo(const Eigen::Vector3d& p_object) const;
};

struct SceneHit {
  double t = 0;
  Eigen::Vector3d p_world, n_world;  // n: outward unit normal
  const SceneObject* object = nullptr;
};

// The objects of one scene, with ray queries in the world frame.
class Scene {
 public:
  std::string name;
  std::vector<SceneObject> objects;

  // Closest hit along a world ray (unit d) with t in (t_min, t_max).
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, SceneHit* hit) const;
  // True if anything blocks the segment o + t d, t in (t_min, t_max).
  bool Occluded(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max) const;
};

// The named scene (cup, sphere, ballbar, plate, tuber) at a random pose with
// conveyor wobble, drawn from `seed`. Texture contrast and wavelength from
// `render`.
Scene MakeScene(const std::string& name, const ScenesSpec& spec, const RenderSpec& render, uint64_t seed);

// Dense samples of every object's surface in the world frame.
std::vector<Eigen::Vector3d> SampleSceneSurface(const Scene& scene, double spacing_mm);

}  // namespace stereorig
