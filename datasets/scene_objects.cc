#include "datasets/scene_objects.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "datasets/rng.h"

namespace stereorig {

namespace {

constexpr double kDeg = M_PI / 180.0;

// Entry and exit of a ray through a sphere; false if it misses.
bool SphereSpan(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r, double* t0,
                double* t1) {
  const Eigen::Vector3d oc = o - c;
  const double b = oc.dot(d);
  const double disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0) return false;
  const double s = std::sqrt(disc);
  *t0 = -b - s;
  *t1 = -b + s;
  return true;
}

class SphereShape : public Shape {
 public:
  SphereShape(const Eigen::Vector3d& c, double r) : c_(c), r_(r) {}
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                 Eigen::Vector3d* n) const override {
    double t0, t1;
    if (!SphereSpan(o, d, c_, r_, &t0, &t1)) return false;
    const double th = t0 > t_min ? t0 : t1;
    if (th <= t_min || th >= t_max) return false;
    *t = th;
    *n = (o + th * d - c_) / r_;
    return true;
  }
  void Sample(double sp, std::vector<Eigen::Vector3d>* out) const override {
    const int nt = static_cast<int>(std::ceil(M_PI * r_ / sp)) + 1;
    for (int i = 0; i <= nt; ++i) {
      const double th = M_PI * i / nt;
      const int np = std::max(1, static_cast<int>(std::ceil(2 * M_PI * r_ * std::sin(th) / sp)));
      for (int j = 0; j < np; ++j) {
        const double ph = 2 * M_PI * j / np;
        out->push_back(c_ +
                       r_ * Eigen::Vector3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
      }
    }
  }

 private:
  Eigen::Vector3d c_;
  double r_;
};

class TubeShape : public Shape {
 public:
  TubeShape(double r, double lo, double hi, int axis)
      : r_(r), lo_(lo), hi_(hi), a_(axis), i_((axis + 1) % 3), j_((axis + 2) % 3) {}
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                 Eigen::Vector3d* n) const override {
    const double A = d[i_] * d[i_] + d[j_] * d[j_];
    if (A < 1e-14) return false;
    const double B = o[i_] * d[i_] + o[j_] * d[j_];
    const double C = o[i_] * o[i_] + o[j_] * o[j_] - r_ * r_;
    const double disc = B * B - A * C;
    if (disc < 0) return false;
    const double s = std::sqrt(disc);
    for (double th : {(-B - s) / A, (-B + s) / A}) {
      if (th <= t_min || th >= t_max) continue;
      const Eigen::Vector3d p = o + th * d;
      if (p[a_] < lo_ || p[a_] > hi_) continue;
      *t = th;
      *n = Eigen::Vector3d::Zero();
      (*n)[i_] = p[i_] / r_;
      (*n)[j_] = p[j_] / r_;
      return true;
    }
    return false;
  }
  void Sample(double sp, std::vector<Eigen::Vector3d>* out) const override {
    const int na = static_cast<int>(std::ceil((hi_ - lo_) / sp));
    const int nc = static_cast<int>(std::ceil(2 * M_PI * r_ / sp));
    for (int k = 0; k <= na; ++k) {
      for (int c = 0; c < nc; ++c) {
        Eigen::Vector3d p;
        p[a_] = lo_ + (hi_ - lo_) * k / na;
        p[i_] = r_ * std::cos(2 * M_PI * c / nc);
        p[j_] = r_ * std::sin(2 * M_PI * c / nc);
        out->push_back(p);
      }
    }
  }

 private:
  double r_, lo_, hi_;
  int a_, i_, j_;
};

class DiskShape : public Shape {
 public:
  DiskShape(double z0, double r0, double r1, bool up) : z0_(z0), r0_(r0), r1_(r1), up_(up) {}
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                 Eigen::Vector3d* n) const override {
    if (std::abs(d.z()) < 1e-14) return false;
    const double th = (z0_ - o.z()) / d.z();
    if (th <= t_min || th >= t_max) return false;
    const double x = o.x() + th * d.x(), y = o.y() + th * d.y();
    const double rho2 = x * x + y * y;
    if (rho2 < r0_ * r0_ || rho2 > r1_ * r1_) return false;
    *t = th;
    *n = Eigen::Vector3d(0, 0, up_ ? 1 : -1);
    return true;
  }
  void Sample(double sp, std::vector<Eigen::Vector3d>* out) const override {
    const int nr = std::max(1, static_cast<int>(std::ceil((r1_ - r0_) / sp)));
    for (int k = 0; k <= nr; ++k) {
      const double rho = r0_ + (r1_ - r0_) * k / nr;
      const int nc = std::max(1, static_cast<int>(std::ceil(2 * M_PI * rho / sp)));
      for (int c = 0; c < nc; ++c) {
        out->emplace_back(rho * std::cos(2 * M_PI * c / nc), rho * std::sin(2 * M_PI * c / nc), z0_);
      }
    }
  }

 private:
  double z0_, r0_, r1_;
  bool up_;
};

class TorusShape : public Shape {
 public:
  TorusShape(double R, double r, double zc) : R_(R), r_(r), zc_(zc) {}
  double Sdf(const Eigen::Vector3d& p) const {
    const double rho = std::hypot(p.x(), p.y());
    return std::hypot(rho - R_, p.z() - zc_) - r_;
  }
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                 Eigen::Vector3d* n) const override {
    double t0, t1;
    if (!SphereSpan(o, d, Eigen::Vector3d(0, 0, zc_), R_ + r_, &t0, &t1)) return false;
    // The slab |z - zc| <= r bounds the torus more tightly for steep rays.
    if (std::abs(d.z()) > 1e-12) {
      double s0 = (zc_ - r_ - o.z()) / d.z(), s1 = (zc_ + r_ - o.z()) / d.z();
      if (s0 > s1) std::swap(s0, s1);
      t0 = std::max(t0, s0);
      t1 = std::min(t1, s1);
    } else if (std::abs(o.z() - zc_) > r_) {
      return false;
    }
    double th = std::max(t0, t_min);
    const double t_end = std::min(t1, t_max);
    if (th >= t_end) return false;
    if (Sdf(o + th * d) < 0) return false;  // starts inside the bead: not a ray we cast
    for (int it = 0; it < 400 && th < t_end; ++it) {
      const double s = Sdf(o + th * d);
      if (s < 1e-7) {
        if (th <= t_min) return false;
        const Eigen::Vector3d p = o + th * d;
        const double rho = std::hypot(p.x(), p.y());
        *t = th;
        *n = Eigen::Vector3d(p.x() * (1 - R_ / rho), p.y() * (1 - R_ / rho), p.z() - zc_).normalized();
        return true;
      }
      th += s;
    }
    return false;
  }
  void Sample(double sp, std::vector<Eigen::Vector3d>* out) const override {
    const int nu = static_cast<int>(std::ceil(2 * M_PI * (R_ + r_) / sp));
    const int nv = static_cast<int>(std::ceil(2 * M_PI * r_ / sp));
    for (int i = 0; i < nu; ++i) {
      const double u = 2 * M_PI * i / nu;
      for (int j = 0; j < nv; ++j) {
        const double v = 2 * M_PI * j / nv;
        const double rho = R_ + r_ * std::cos(v);
        out->emplace_back(rho * std::cos(u), rho * std::sin(u), zc_ + r_ * std::sin(v));
      }
    }
  }

 private:
  double R_, r_, zc_;
};

class BoxShape : public Shape {
 public:
  explicit BoxShape(const Eigen::Vector3d& h) : h_(h) {}
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                 Eigen::Vector3d* n) const override {
    double tn = -1e300, tf = 1e300;
    int an = -1, af = -1;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(d[a]) < 1e-15) {
        if (std::abs(o[a]) > h_[a]) return false;
        continue;
      }
      double t0 = (-h_[a] - o[a]) / d[a], t1 = (h_[a] - o[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      if (t0 > tn) tn = t0, an = a;
      if (t1 < tf) tf = t1, af = a;
    }
    if (tn > tf) return false;
    if (tn > t_min && tn < t_max && an >= 0) {
      *t = tn;
      *n = Eigen::Vector3d::Zero();
      (*n)[an] = d[an] > 0 ? -1 : 1;
      return true;
    }
    if (tf > t_min && tf < t_max && af >= 0) {
      *t = tf;
      *n = Eigen::Vector3d::Zero();
      (*n)[af] = d[af] > 0 ? 1 : -1;
      return true;
    }
    return false;
  }
  void Sample(double sp, std::vector<Eigen::Vector3d>* out) const override {
    for (int a = 0; a < 3; ++a) {
      const int i = (a + 1) % 3, j = (a + 2) % 3;
      const int ni = static_cast<int>(std::ceil(2 * h_[i] / sp)), nj = static_cast<int>(std::ceil(2 * h_[j] / sp));
      for (int s : {-1, 1}) {
        for (int u = 0; u <= ni; ++u) {
          for (int v = 0; v <= nj; ++v) {
            Eigen::Vector3d p;
            p[a] = s * h_[a];
            p[i] = -h_[i] + 2 * h_[i] * u / ni;
            p[j] = -h_[j] + 2 * h_[j] * v / nj;
            out->push_back(p);
          }
        }
      }
    }
  }

 private:
  Eigen::Vector3d h_;
};

// sin(x) to ~6e-8 absolute, about 3x faster than libm's: the tuber's bump
// field is evaluated millions of times per image. It DEFINES the shape (the
// renderer and the ground-truth samples both use it), so its error is not an
// error of the truth.
inline double FastSin(double x) {
  x -= 2 * M_PI * std::nearbyint(x * (0.5 / M_PI));  // [-pi, pi]
  if (x > 0.5 * M_PI) x = M_PI - x;
  if (x < -0.5 * M_PI) x = -M_PI - x;  // [-pi/2, pi/2], same sine
  const double x2 = x * x;
  return x *
         (1 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880 + x2 * (-1.0 / 39916800))))));
}

class BumpyEllipsoidShape : public Shape {
 public:
  static constexpr int kTerms = 6;
  static constexpr double kMaxFreq = 5.0;
  BumpyEllipsoidShape(const Eigen::Vector3d& axes, double bump, uint64_t seed) : axes_(axes), bump_(bump) {
    Rng rng(seed);
    for (int k = 0; k < kTerms; ++k) {
      Eigen::Vector3d g(rng.Normal(), rng.Normal(), rng.Normal());
      g_[k] = g.normalized();
      f_[k] = rng.Uniform(2.0, kMaxFreq);
      phase_[k] = rng.Uniform(0, 2 * M_PI);
    }
    // |grad h| <= bump * max f on the unit sphere; F = |u| - 1 - h(u/|u|)
    // changes along a unit step in u by at most lipschitz_.
    double sum_f = 0;
    for (int k = 0; k < kTerms; ++k) sum_f += f_[k];
    lipschitz_ = 1.0 + bump_ * (sum_f / kTerms) / (1.0 - bump_);
  }
  double H(const Eigen::Vector3d& unit) const {
    double h = 0;
    for (int k = 0; k < kTerms; ++k) h += FastSin(f_[k] * g_[k].dot(unit) + phase_[k]);
    return bump_ * h / kTerms;
  }
  double F(const Eigen::Vector3d& u) const {
    const double r = u.norm();
    return r - 1.0 - H(u / r);
  }
  bool Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max, double* t,
                 Eigen::Vector3d* n) const override {
    const Eigen::Vector3d ou = o.cwiseQuotient(axes_), du = d.cwiseQuotient(axes_);
    const double dn = du.norm();
    const Eigen::Vector3d du1 = du / dn;
    double s0, s1;  // along du1, in u units
    if (!SphereSpan(ou, du1, Eigen::Vector3d::Zero(), 1.0 + bump_ + 1e-9, &s0, &s1)) return false;
    double s = std::max(s0, t_min * dn);
    const double s_end = std::min(s1, t_max * dn);
    if (s >= s_end) return false;
    const double f_start = F(ou + s * du1);
    if (f_start < 0) return false;  // starts inside: not a ray we cast
    // Fast path: a ray that meets the inner bound |u| = 1 - bump steeply
    // (cos > 0.5, i.e. within 60 degrees of the radial direction) crosses the
    // shell once, because the bumps' slope (<= bump * max frequency = 0.25 by
    // default) is far below that; the surface is then the only root of F
    // between the start and the inner bound: Illinois regula falsi finds it.
    double si0, si1;
    if (bump_ * kMaxFreq < 0.5 && SphereSpan(ou, du1, Eigen::Vector3d::Zero(), 1.0 - bump_, &si0, &si1) && si0 > s &&
        si0 < s_end && std::abs(du1.dot(ou + si0 * du1)) > 0.5 * (1.0 - bump_)) {
      double a = s, fa = f_start, b = si0, fb = F(ou + si0 * du1);
      int side = 0;
      for (int it = 0; it < 100 && fb < 0; ++it) {
        const double c = (a * fb - b * fa) / (fb - fa);
        const double fc = F(ou + c * du1);
        if (std::abs(fc) < 1e-8 || b - a < 1e-10) {
          if (c <= t_min * dn) return false;
          return Hit(ou + c * du1, c / dn, t, n);
        }
        if (fc > 0) {
          a = c, fa = fc;
          if (side == 1) fb *= 0.5;
          side = 1;
        } else {
          b = c, fb = fc;
          if (side == -1) fa *= 0.5;
          side = -1;
        }
      }
    }
    // Sphere tracing (never steps past the surface: |dF/ds| <= lipschitz_),
    // sped up near the surface by secant steps, accepted only if they land
    // within 1e-8 of the surface (u units, ~3e-7 mm) or short of it.
    double s_prev = s, f_prev = -1;
    for (int it = 0; it < 600 && s < s_end; ++it) {
      double f = F(ou + s * du1);
      if (f >= 1e-8 && f < 1e-3 && f_prev > f) {
        const double s_sec = s + f * (s - s_prev) / (f_prev - f);
        const double f_sec = F(ou + s_sec * du1);
        if (std::abs(f_sec) < 1e-8 || f_sec > 0) {
          s_prev = s, f_prev = f;
          s = s_sec, f = f_sec;
        }
      }
      if (f < 1e-8) {
        if (s <= t_min * dn || s >= s_end) return false;
        return Hit(ou + s * du1, s / dn, t, n);
      }
      s_prev = s, f_prev = f;
      s += f / lipschitz_;
    }
    return false;
  }
  // Sets the hit at u (object frame / axes): *t, and the normal from F's gradient.
  bool Hit(const Eigen::Vector3d& u, double t_hit, double* t, Eigen::Vector3d* n) const {
    *t = t_hit;
    const double e = 1e-6;
    Eigen::Vector3d grad;
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d du_e = Eigen::Vector3d::Zero();
      du_e[a] = e;
      grad[a] = (F(u + du_e) - F(u - du_e)) / (2 * e);
    }
    *n = grad.cwiseQuotient(axes_).normalized();  // chain rule: dF/dp = dF/du / axes
    return true;
  }
  void Sample(double sp, std::vector<Eigen::Vector3d>* out) const override {
    const double stretch = axes_.maxCoeff() * (1 + bump_ + bump_ * kMaxFreq);
    const int nt = static_cast<int>(std::ceil(M_PI * stretch / sp)) + 1;
    for (int i = 0; i <= nt; ++i) {
      const double th = M_PI * i / nt;
      const int np = std::max(1, static_cast<int>(std::ceil(2 * M_PI * stretch * std::sin(th) / sp)));
      for (int j = 0; j < np; ++j) {
        const double ph = 2 * M_PI * j / np;
        const Eigen::Vector3d w(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
        out->push_back(axes_.cwiseProduct(w * (1.0 + H(w))));
      }
    }
  }

  Eigen::Vector3d axes_;
  double bump_;
  Eigen::Vector3d g_[kTerms];
  double f_[kTerms], phase_[kTerms];
  double lipschitz_;
};

std::string Fmt(double x) { return FormatDouble(x); }

}  // namespace

std::unique_ptr<Shape> MakeSphere(const Eigen::Vector3d& c, double r) { return std::make_unique<SphereShape>(c, r); }
std::unique_ptr<Shape> MakeTube(double r, double lo, double hi, int axis) {
  return std::make_unique<TubeShape>(r, lo, hi, axis);
}
std::unique_ptr<Shape> MakeDisk(double z0, double r0, double r1, bool up) {
  return std::make_unique<DiskShape>(z0, r0, r1, up);
}
std::unique_ptr<Shape> MakeRimTorus(double R, double r, double zc) { return std::make_unique<TorusShape>(R, r, zc); }
std::unique_ptr<Shape> MakeBox(const Eigen::Vector3d& h) { return std::make_unique<BoxShape>(h); }
std::unique_ptr<Shape> MakeBumpyEllipsoid(const Eigen::Vector3d& axes, double bump, uint64_t seed) {
  return std::make_unique<BumpyEllipsoidShape>(axes, bump, seed);
}

double SceneObject::Albedo(const Eigen::Vector3d& p) const {
  if (texture_contrast == 0) return albedo;
  double t = 0;
  for (int k = 0; k < 4; ++k) t += std::sin(texture_k[k].dot(p) + texture_phase[k]);
  return albedo * (1.0 + texture_contrast * 0.25 * t);
}

namespace {

// Tests the ray o + t d, t in [t_min, t_max), against every shape of the
// objects whose bounding sphere it crosses, each in its object's frame.
// on_hit(object, t, n_object) is called for each shape hit before the
// current t_max and returns the t_max to go on with; at or below t_min the
// walk stops.
template <class OnHit>
void WalkShapeHits(const std::vector<SceneObject>& objects, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                   double t_min, double t_max, OnHit&& on_hit) {
  for (const SceneObject& obj : objects) {
    double b0, b1;
    if (!SphereSpan(o, d, obj.bound_center_world, obj.bound_radius_mm, &b0, &b1)) continue;
    if (b1 <= t_min || b0 >= t_max) continue;
    const Eigen::Vector3d oo = obj.object_from_world * o;
    const Eigen::Vector3d dd = obj.object_from_world.rotation() * d;
    for (const auto& shape : obj.shapes) {
      double t;
      Eigen::Vector3d n;
      if (shape->Intersect(oo, dd, t_min, t_max, &t, &n)) {
        t_max = on_hit(obj, t, n);
        if (t_max <= t_min) return;
      }
    }
  }
}

}  // namespace

bool Scene::Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max,
                      SceneHit* hit) const {
  bool found = false;
  WalkShapeHits(objects, o, d, t_min, t_max, [&](const SceneObject& obj, double t, const Eigen::Vector3d& n) {
    found = true;  // the nearest so far: search on only before it
    hit->t = t;
    hit->n_world = obj.world_from_object.rotation() * n;
    hit->object = &obj;
    return t;
  });
  if (found) hit->p_world = o + hit->t * d;
  return found;
}

bool Scene::Occluded(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max) const {
  bool hit = false;
  WalkShapeHits(objects, o, d, t_min, t_max, [&](const SceneObject&, double, const Eigen::Vector3d&) {
    hit = true;  // any hit will do: stop
    return t_min;
  });
  return hit;
}

namespace {

// Places an object: `center_object` (object frame) goes to the world origin
// plus the conveyor shift; axes turned by base, then yaw about world y (the
// vertical), then the rocking tilt about world x and z.
Pose ConveyorPose(const Eigen::Matrix3d& base, const Eigen::Vector3d& center_object, double yaw_range_deg,
                  const ScenesSpec& spec, Rng* rng) {
  const double yaw = rng->Uniform(-yaw_range_deg, yaw_range_deg) * kDeg;
  const double tx = rng->Uniform(-spec.wobble_tilt_deg, spec.wobble_tilt_deg) * kDeg;
  const double tz = rng->Uniform(-spec.wobble_tilt_deg, spec.wobble_tilt_deg) * kDeg;
  const Eigen::Vector3d shift(rng->Uniform(-spec.wobble_shift_mm, spec.wobble_shift_mm), 0,
                              rng->Uniform(-spec.wobble_shift_mm, spec.wobble_shift_mm));
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(tx, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(tz, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()))
          .toRotationMatrix() *
      base;
  return Pose(r, shift - r * center_object);
}

void Finish(SceneObject* obj, const Eigen::Vector3d& bound_center_object, double bound_radius, const RenderSpec& render,
            Rng* rng) {
  obj->object_from_world = obj->world_from_object.Inverse();
  obj->bound_center_world = obj->world_from_object * bound_center_object;
  obj->bound_radius_mm = bound_radius;
  obj->texture_contrast = render.texture_contrast;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d g = Eigen::Vector3d(rng->Normal(), rng->Normal(), rng->Normal()).normalized();
    obj->texture_k[k] = g * (2 * M_PI / render.texture_wavelength_mm) * rng->Uniform(0.6, 1.4);
    obj->texture_phase[k] = rng->Uniform(0, 2 * M_PI);
  }
}

SceneObject MakeBall(int id, const std::string& what, double diameter, const Pose& world_from_object, double albedo,
                     const RenderSpec& render, Rng* rng) {
  SceneObject o;
  o.id = id;
  o.type = "sphere";
  o.description = what;
  o.albedo = albedo;
  o.world_from_object = world_from_object;
  o.shapes.push_back(MakeSphere(Eigen::Vector3d::Zero(), 0.5 * diameter));
  o.parameters_yaml = "diameter_mm: " + Fmt(diameter) + "\n";
  Finish(&o, Eigen::Vector3d::Zero(), 0.5 * diameter + 1e-6, render, rng);
  return o;
}

}  // namespace

Scene MakeScene(const std::string& name, const ScenesSpec& spec, const RenderSpec& render, uint64_t seed) {
  Rng rng(seed);
  Scene scene;
  scene.name = name;
  const Eigen::Matrix3d upright =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();  // object z -> world up (-y)
  if (name == "cup") {
    const double R = 0.5 * spec.cup_diameter_mm, H = spec.cup_height_mm;
    const double wall = 3.0, bottom = 6.0, bead = 2.5;  // mm: wall, floor thickness, rim bead radius
    const double rim_major = R - 0.5 * wall;
    SceneObject o;
    o.id = 1;
    o.type = "cup";
    o.description = "ceramic cup: open cylinder with a floor and a rounded rim bead (no handle)";
    o.albedo = spec.cup_albedo;
    o.world_from_object = ConveyorPose(upright, Eigen::Vector3d(0, 0, 0.5 * H), 180.0, spec, &rng);
    o.shapes.push_back(MakeTube(R, 0, H, 2));
    o.shapes.push_back(MakeTube(R - wall, bottom, H, 2));
    o.shapes.push_back(MakeDisk(0, 0, R, false));
    o.shapes.push_back(MakeDisk(bottom, 0, R - wall, true));
    o.shapes.push_back(MakeRimTorus(rim_major, bead, H));
    o.inside_solid = [=](const Eigen::Vector3d& p) {
      const double rho = std::hypot(p.x(), p.y());
      const double e = 1e-6;
      const bool in_bead = std::hypot(rho - rim_major, p.z() - H) < bead - e;
      const bool in_wall = rho > R - wall + e && rho < R - e && p.z() > e && p.z() < H - e;
      return in_bead || in_wall;
    };
    o.parameters_yaml = "outer_diameter_mm: " + Fmt(2 * R) + "\nheight_mm: " + Fmt(H) + "\nwall_mm: " + Fmt(wall) +
                        "\nfloor_mm: " + Fmt(bottom) + "\nrim_bead_radius_mm: " + Fmt(bead) +
                        "\nrim_bead_major_radius_mm: " + Fmt(rim_major) +
                        "\nframe: \"origin at the centre of the outside bottom, z up the axis\"\n";
    Finish(&o, Eigen::Vector3d(0, 0, 0.5 * H), std::hypot(R + bead, 0.5 * H + bead) + 1e-6, render, &rng);
    scene.objects.push_back(std::move(o));
  } else if (name == "sphere") {
    const Pose pose = ConveyorPose(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 180.0, spec, &rng);
    scene.objects.push_back(
        MakeBall(1, "certified matte sphere", spec.sphere_diameter_mm, pose, spec.artifact_albedo, render, &rng));
  } else if (name == "ballbar") {
    const double D = spec.ballbar_distance_mm, r = 0.5 * spec.ballbar_sphere_diameter_mm;
    // The default modules' two views overlap in only ~70 x 110 mm at the
    // object (90 mm baseline, 6 degrees of verging), so the bar stands
    // steeply, 60 +- 10 degrees from the belt, to keep both balls in all views.
    const double lean = (60.0 + rng.Uniform(-10, 10)) * kDeg;
    const Pose bar = ConveyorPose(Eigen::AngleAxisd(lean, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                                  Eigen::Vector3d::Zero(), 15.0, spec, &rng);
    for (int k = 0; k < 2; ++k) {
      const Pose ball = bar * Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d((k == 0 ? -0.5 : 0.5) * D, 0, 0));
      scene.objects.push_back(MakeBall(k + 1, k == 0 ? "ball bar: ball A" : "ball bar: ball B",
                                       spec.ballbar_sphere_diameter_mm, ball, spec.artifact_albedo, render, &rng));
    }
    SceneObject rod;
    rod.id = 3;
    rod.type = "tube";
    rod.description = "ball bar: rod between the balls (axis = object x)";
    rod.albedo = 0.3;
    rod.world_from_object = bar;
    const double rod_r = 4.0;
    rod.shapes.push_back(MakeTube(rod_r, -0.5 * D, 0.5 * D, 0));
    rod.inside_solid = [=](const Eigen::Vector3d& p) {
      return (p - Eigen::Vector3d(-0.5 * D, 0, 0)).norm() < r || (p - Eigen::Vector3d(0.5 * D, 0, 0)).norm() < r;
    };
    rod.parameters_yaml = "radius_mm: " + Fmt(rod_r) + "\nfrom_x_mm: " + Fmt(-0.5 * D) + "\nto_x_mm: " + Fmt(0.5 * D) +
                          "\ncenter_distance_mm: " + Fmt(D) + "\n";
    Finish(&rod, Eigen::Vector3d::Zero(), std::hypot(0.5 * D, rod_r) + 1e-6, render, &rng);
    scene.objects.push_back(std::move(rod));
  } else if (name == "plate") {
    SceneObject o;
    o.id = 1;
    o.type = "box";
    o.description = "flatness plate: a box, its large faces normal to object z (facing the modules)";
    o.albedo = spec.artifact_albedo;
    o.world_from_object = ConveyorPose(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 10.0, spec, &rng);
    const Eigen::Vector3d half = 0.5 * spec.plate_size_mm;
    o.shapes.push_back(MakeBox(half));
    o.parameters_yaml = "size_mm: [" + Fmt(spec.plate_size_mm.x()) + ", " + Fmt(spec.plate_size_mm.y()) + ", " +
                        Fmt(spec.plate_size_mm.z()) + "]\nframe: \"centred on the box, edges along the axes\"\n";
    Finish(&o, Eigen::Vector3d::Zero(), half.norm() + 1e-6, render, &rng);
    scene.objects.push_back(std::move(o));
  } else if (name == "tuber") {
    SceneObject o;
    o.id = 1;
    o.type = "bumpy_ellipsoid";
    o.description = "tuber: ellipsoid with low-frequency radial bumps, |u| = 1 + h(u/|u|), u = p / semi_axes";
    o.albedo = spec.tuber_albedo;
    o.world_from_object = ConveyorPose(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 45.0, spec, &rng);
    const uint64_t bump_seed = rng.Next();
    o.shapes.push_back(MakeBumpyEllipsoid(spec.tuber_semi_axes_mm, spec.tuber_bump, bump_seed));
    const auto* e = static_cast<const BumpyEllipsoidShape*>(o.shapes.back().get());
    std::ostringstream p;
    p << "semi_axes_mm: [" << Fmt(e->axes_.x()) << ", " << Fmt(e->axes_.y()) << ", " << Fmt(e->axes_.z()) << "]\n"
      << "bump: " << Fmt(e->bump_) << "\n"
      << "# h(w) = bump / " << BumpyEllipsoidShape::kTerms << " * sum_k sin(frequency_k * direction_k . w + phase_k)\n"
      << "# (sin evaluated to ~6e-8, i.e. the shape is exact to ~1e-7 mm)\n"
      << "terms:\n";
    for (int k = 0; k < BumpyEllipsoidShape::kTerms; ++k) {
      p << "  - {direction: [" << Fmt(e->g_[k].x()) << ", " << Fmt(e->g_[k].y()) << ", " << Fmt(e->g_[k].z())
        << "], frequency: " << Fmt(e->f_[k]) << ", phase: " << Fmt(e->phase_[k]) << "}\n";
    }
    o.parameters_yaml = p.str();
    Finish(&o, Eigen::Vector3d::Zero(), spec.tuber_semi_axes_mm.maxCoeff() * (1 + spec.tuber_bump) + 1e-6, render,
           &rng);
    scene.objects.push_back(std::move(o));
  } else {
    throw InputError("scene", "unknown scene '" + name + "'");
  }
  return scene;
}

std::vector<Eigen::Vector3d> SampleSceneSurface(const Scene& scene, double spacing_mm) {
  std::vector<Eigen::Vector3d> out;
  for (const SceneObject& obj : scene.objects) {
    std::vector<Eigen::Vector3d> local;
    for (const auto& s : obj.shapes) s->Sample(spacing_mm, &local);
    for (const Eigen::Vector3d& p : local) {
      if (obj.inside_solid && obj.inside_solid(p)) continue;
      out.push_back(obj.world_from_object * p);
    }
  }
  return out;
}

}  // namespace stereorig
