#include "reconstruct/free_space.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/core.hpp>

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

// Module j's rectified left frame: a point's pixel and disparity there.
class ModuleProjection {
 public:
  explicit ModuleProjection(const FreeSpaceView& view)
      : g_(view.geometry),
        r_(g_.rect_from_left * view.module_from_reference.rotation()),
        t_(g_.rect_from_left * view.module_from_reference.translation_mm()) {}

  const RectifiedGeometry& geometry() const { return g_; }
  Eigen::Vector3d Rectified(const Eigen::Vector3f& p_reference_mm) const {
    return r_ * p_reference_mm.cast<double>() + t_;
  }
  Eigen::Vector3d RectifiedDirection(const Eigen::Vector3f& n_reference) const {
    return r_ * n_reference.cast<double>();
  }
  // (u, v) the nearest pixel, *q the pixel and disparity; false if P is
  // behind the camera or outside the image.
  bool Project(const Eigen::Vector3d& p_rect, int* u, int* v, Eigen::Vector3d* q) const {
    if (!(p_rect.z() > 1e-6)) return false;
    *q = g_.PixelAndDisparity(p_rect);
    *u = int(std::lround(q->x())), *v = int(std::lround(q->y()));
    return *u >= 0 && *v >= 0 && *u < g_.size.width && *v < g_.size.height;
  }

 private:
  const RectifiedGeometry& g_;
  Eigen::Matrix3d r_;
  Eigen::Vector3d t_;
};

// The depth buffer of module j: at each pixel of its rectified left image,
// the largest disparity of the other modules' points that face camera j,
// among those `usable` (empty: all); -inf where none. With `owners`,
// `owner` holds that point's (module, index) (the photo check's; the first
// pass, which runs on every capture, has no use for it). Empty if no point
// projects.
struct DepthBuffer {
  cv::Mat disparity;  // CV_32FC1
  cv::Mat owner;      // CV_32SC2
};
DepthBuffer FacingDepthBuffer(int j, const FreeSpaceView& view, const ModuleProjection& proj,
                              const std::vector<PointCloud>& clouds, const std::vector<std::vector<uint8_t>>& usable,
                              const FreeSpaceOptions& options, bool owners) {
  const float none = -std::numeric_limits<float>::infinity();
  const Eigen::Vector3f eye = view.camera_centre_reference_mm.cast<float>();
  DepthBuffer buffer;
  for (int k = 0; k < int(clouds.size()); ++k) {
    if (k == j) continue;
    const PointCloud& c = clouds[k];
    for (size_t i = 0; i < c.size(); ++i) {
      if (!usable.empty() && !usable[k][i]) continue;
      const Eigen::Vector3f to_eye = eye - c.xyz_mm[i];
      const float dist = to_eye.norm();
      if (!(c.normal[i].dot(to_eye) > float(options.min_facing_cos) * dist)) continue;
      int u, v;
      Eigen::Vector3d q;
      if (!proj.Project(proj.Rectified(c.xyz_mm[i]), &u, &v, &q)) continue;
      if (buffer.disparity.empty()) {
        buffer.disparity = cv::Mat(proj.geometry().size, CV_32FC1, cv::Scalar(none));
        if (owners) buffer.owner = cv::Mat(proj.geometry().size, CV_32SC2, cv::Scalar(-1, -1));
      }
      float& b = buffer.disparity.at<float>(v, u);
      if (float(q.z()) > b) {
        b = float(q.z());
        if (owners) buffer.owner.at<cv::Vec2i>(v, u) = cv::Vec2i(k, int(i));
      }
    }
  }
  return buffer;
}

// The disparity slopes (px/px) in j's image of the plane through p_rect
// with normal n_rect (rectified frame): n.X = h gives d = B (n_x (u - cx) +
// n_y (v - cy) + n_z f) / h, so d steps by B n_x / h and B n_y / h per px.
// Clamped to the steepest facing slope at that depth, B / Z tan(acos(
// min_facing_cos)).
Eigen::Vector2d PlaneSlopes(const RectifiedGeometry& g, const Eigen::Vector3d& p_rect, const Eigen::Vector3d& n_rect,
                            const FreeSpaceOptions& options) {
  const double cos_max = std::max(options.min_facing_cos, 0.05);
  const double tan_max = std::sqrt(1 - cos_max * cos_max) / cos_max;
  const double max_slope = g.baseline_mm / p_rect.z() * tan_max;
  const double h = n_rect.dot(p_rect);
  if (!(std::abs(h) > 1e-9)) return Eigen::Vector2d::Zero();
  return Eigen::Vector2d(std::clamp(g.baseline_mm * n_rect.x() / h, -max_slope, max_slope),
                         std::clamp(g.baseline_mm * n_rect.y() / h, -max_slope, max_slope));
}

// Below this foreshortening of the right view, s = 1 - dd/dx, the right
// camera grazes the surface: a window of 9 left columns covers under 3 right
// ones, and a correct match does not correlate (the fill diagnosis's
// lowest bin, fill_diagnosis.h; the matcher's distinctness clamp).
constexpr double kRightViewGrazing = 0.3;

// Whether the nearer point at buffer pixel (x, y) counts against module j's
// point, by j's own rectified pair: it does where the pair correlates there
// (the best ZNCC of the window, warped by that point's own plane, at its
// plane's disparity at the pixel's centre and 0.5 px either side, >=
// min_zncc), and where the pair cannot tell: j's right camera grazes that
// plane, or no window can be taken (off the image, or a flat or blank
// window: rows outside the module's rectified band are 0).
bool CountsByTheModulesPair(const FreeSpaceView& view, const ModuleProjection& proj,
                            const std::vector<PointCloud>& clouds, const DepthBuffer& buffer, int x, int y,
                            const FreeSpaceOptions& options) {
  const cv::Vec2i owner = buffer.owner.at<cv::Vec2i>(y, x);
  const PointCloud& c = clouds[owner[0]];
  const Eigen::Vector3d q_rect = proj.Rectified(c.xyz_mm[owner[1]]);
  const Eigen::Vector2d slopes =
      PlaneSlopes(proj.geometry(), q_rect, proj.RectifiedDirection(c.normal[owner[1]]), options);
  if (1 - slopes.x() < kRightViewGrazing) return true;
  // The point lies somewhere in its pixel: its plane's disparity at the
  // pixel's centre.
  const Eigen::Vector3d q = proj.geometry().PixelAndDisparity(q_rect);
  const double d = q.z() + slopes.x() * (x - q.x()) + slopes.y() * (y - q.y());
  double best = -1;
  for (const double step : {-0.5, 0.0, 0.5})
    best = std::max(best, WindowZncc(view.left_rectified, view.right_rectified, x, y, d + step, slopes.x(), slopes.y(),
                                     options.window));
  return best <= -1 || best >= options.min_zncc;
}

// Whether module j's point i is refuted by `buffer`; with photo_check,
// only by the buffer pixels CountsByTheModulesPair counts.
bool SeenThrough(const FreeSpaceView& view, const ModuleProjection& proj, const std::vector<PointCloud>& clouds, int j,
                 size_t i, const DepthBuffer& buffer, bool photo_check, const FreeSpaceOptions& options) {
  const RectifiedGeometry& g = proj.geometry();
  const PointCloud& c = clouds[j];
  const Eigen::Vector3d p_rect = proj.Rectified(c.xyz_mm[i]);
  int u, v;
  Eigen::Vector3d q;
  if (!proj.Project(p_rect, &u, &v, &q)) return false;
  // P's own surface, its normal's plane: a correct point of another module
  // on the same surface, one or two px away, differs by the plane's step,
  // not by the margin.
  const Eigen::Vector2d slopes = PlaneSlopes(g, p_rect, proj.RectifiedDirection(c.normal[i]), options);
  const int rad = options.window_radius_px;
  int support = 0;
  for (int y = std::max(0, v - rad); y <= std::min(g.size.height - 1, v + rad); ++y) {
    const float* b = buffer.disparity.ptr<float>(y);
    for (int x = std::max(0, u - rad); x <= std::min(g.size.width - 1, u + rad); ++x) {
      const double front = q.z() + slopes.x() * (x - q.x()) + slopes.y() * (y - q.y()) + options.margin_px;
      if (b[x] > front && (!photo_check || CountsByTheModulesPair(view, proj, clouds, buffer, x, y, options)))
        ++support;
    }
  }
  return support >= options.min_support;
}

// Module j's surfaces: a label per point, points joined through the same
// or 4-neighbouring pixels of j's rectified left image when they lie within
// max_edge_mm of each other (union-find over the points).
std::vector<int> SurfaceLabels(const ModuleProjection& proj, const PointCloud& c, double max_edge_mm) {
  std::vector<int> parent(c.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  const float max_edge2 = float(max_edge_mm * max_edge_mm);
  auto join = [&](int a, int b) {
    if ((c.xyz_mm[a] - c.xyz_mm[b]).squaredNorm() > max_edge2) return;
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  cv::Mat first(proj.geometry().size, CV_32SC1, cv::Scalar(-1));  // the first point at each pixel
  for (size_t i = 0; i < c.size(); ++i) {
    int u, v;
    Eigen::Vector3d q;
    if (!proj.Project(proj.Rectified(c.xyz_mm[i]), &u, &v, &q)) continue;
    int& f = first.at<int>(v, u);
    if (f < 0) {
      f = int(i);
    } else {
      join(f, int(i));
    }
  }
  for (int y = 0; y < first.rows; ++y) {
    const int* row = first.ptr<int>(y);
    const int* below = y + 1 < first.rows ? first.ptr<int>(y + 1) : nullptr;
    for (int x = 0; x < first.cols; ++x) {
      if (row[x] < 0) continue;
      if (x + 1 < first.cols && row[x + 1] >= 0) join(row[x], row[x + 1]);
      if (below && below[x] >= 0) join(row[x], below[x]);
    }
  }
  std::vector<int> label(c.size());
  for (size_t i = 0; i < c.size(); ++i) label[i] = find(int(i));
  return label;
}

}  // namespace

std::vector<std::vector<uint8_t>> FreeSpaceRefuted(const std::vector<FreeSpaceView>& views,
                                                   const std::vector<PointCloud>& clouds,
                                                   const FreeSpaceOptions& options) {
  STEREORIG_CHECK(views.size() == clouds.size());
  const int nm = int(views.size());
  std::vector<ModuleProjection> projections;
  projections.reserve(nm);
  for (const FreeSpaceView& view : views) projections.emplace_back(view);
  for (int j = 0; j < nm; ++j) {
    const FreeSpaceView& v = views[j];
    if (v.left_rectified.empty() && v.right_rectified.empty()) continue;
    STEREORIG_CHECK(v.left_rectified.type() == CV_8UC1 && v.right_rectified.type() == CV_8UC1 &&
                    v.left_rectified.size() == v.geometry.size && v.right_rectified.size() == v.geometry.size);
  }
  // The test with the buffers of the `usable` points (empty: all), on the
  // points `to_test` flags (empty: all); with photo_check, where module j
  // has its images.
  auto test = [&](const std::vector<std::vector<uint8_t>>& usable, const std::vector<std::vector<uint8_t>>& to_test,
                  bool photo_check) {
    std::vector<std::vector<uint8_t>> refuted(nm);
    for (int j = 0; j < nm; ++j) {
      refuted[j].assign(clouds[j].size(), 0);
      if (clouds[j].size() == 0) continue;
      if (!to_test.empty() && std::find(to_test[j].begin(), to_test[j].end(), 1) == to_test[j].end()) continue;
      const bool check = photo_check && !views[j].left_rectified.empty();
      const DepthBuffer buffer = FacingDepthBuffer(j, views[j], projections[j], clouds, usable, options, check);
      if (buffer.disparity.empty()) continue;
      for (size_t i = 0; i < clouds[j].size(); ++i)
        if (to_test.empty() || to_test[j][i])
          refuted[j][i] = SeenThrough(views[j], projections[j], clouds, j, i, buffer, check, options);
    }
    return refuted;
  };
  std::vector<std::vector<uint8_t>> first = test({}, {}, false);
  bool any_refuted = false;
  for (int j = 0; j < nm; ++j)
    any_refuted = any_refuted || std::find(first[j].begin(), first[j].end(), 1) != first[j].end();
  if (!any_refuted) return first;

  // The surfaces at least surface_fraction refuted go whole.
  std::vector<std::vector<uint8_t>> wrong(nm), usable(nm);
  for (int j = 0; j < nm; ++j) {
    wrong[j].assign(clouds[j].size(), 0);
    if (std::find(first[j].begin(), first[j].end(), 1) != first[j].end()) {
      const std::vector<int> label = SurfaceLabels(projections[j], clouds[j], options.surface_max_edge_mm);
      std::vector<int> size(clouds[j].size(), 0), refuted(clouds[j].size(), 0);
      for (size_t i = 0; i < label.size(); ++i) ++size[label[i]], refuted[label[i]] += first[j][i];
      for (size_t i = 0; i < label.size(); ++i)
        wrong[j][i] = refuted[label[i]] >= options.surface_fraction * size[label[i]];
    }
    usable[j].resize(clouds[j].size());
    for (size_t i = 0; i < clouds[j].size(); ++i) usable[j][i] = !wrong[j][i];
  }
  // Again, without the wrong surfaces as occluders (what they alone refuted
  // stays), on what the first pass refuted off them (with fewer occluders
  // nothing else can be). What is refuted then, or lies on a wrong surface,
  // goes.
  std::vector<std::vector<uint8_t>> again(nm);
  for (int j = 0; j < nm; ++j) {
    again[j].resize(clouds[j].size());
    for (size_t i = 0; i < clouds[j].size(); ++i) again[j][i] = first[j][i] && !wrong[j][i];
  }
  const std::vector<std::vector<uint8_t>> second = test(usable, again, true);
  std::vector<std::vector<uint8_t>> verdict(nm);
  for (int j = 0; j < nm; ++j) {
    verdict[j].assign(clouds[j].size(), uint8_t(FreeSpaceVerdict::kKept));
    for (size_t i = 0; i < clouds[j].size(); ++i) {
      if (wrong[j][i])
        verdict[j][i] = uint8_t(first[j][i] ? FreeSpaceVerdict::kSeenThrough : FreeSpaceVerdict::kOnSeenThroughSurface);
      else if (second[j][i])
        verdict[j][i] = uint8_t(FreeSpaceVerdict::kSeenThrough);
    }
  }
  return verdict;
}

}  // namespace stereorig
