#include "reconstruct/runtime.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "calib/core/capture_image_name.h"
#include "calib/core/input_error.h"
#include "reconstruct/disparity_band.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/free_space.h"
#include "reconstruct/grey_image.h"
#include "reconstruct/hole_fill.h"
#include "reconstruct/lit_mask.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/right_occlusion.h"

namespace stereorig {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<Eigen::Vector3d> VolumeCorners(const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  std::vector<Eigen::Vector3d> corners;
  corners.reserve(8);
  for (int i = 0; i < 8; ++i)
    corners.push_back(centre + 0.5 * Eigen::Vector3d((i & 1 ? 1 : -1) * size.x(), (i & 2 ? 1 : -1) * size.y(),
                                                     (i & 4 ? 1 : -1) * size.z()));
  return corners;
}

// Removes module m's refuted points (FreeSpaceVerdict) from its cloud and
// mesh, marks their pixels kSeenThrough or kSeenThroughSurface and recounts
// the module's report. A point's pixel is
// its reprojection through the module's rectification (the points were
// triangulated from pixel centres, so it rounds back to them).
void RemoveRefuted(const ModulePlan& plan, const std::vector<uint8_t>& refuted, PointCloud* cloud, Mesh* mesh,
                   ModuleReport* report) {
  const Pose module_from_reference = plan.reference_from_module.Inverse();
  const Eigen::Matrix3d r = plan.geometry.rect_from_left * module_from_reference.rotation();
  const Eigen::Vector3d t = plan.geometry.rect_from_left * module_from_reference.translation_mm();
  for (size_t i = 0; i < cloud->size(); ++i) {
    if (!refuted[i]) continue;
    const bool surface = refuted[i] == uint8_t(FreeSpaceVerdict::kOnSeenThroughSurface);
    ++report->seen_through;
    report->seen_through_surface += surface;
    const Eigen::Vector3d q = plan.geometry.PixelAndDisparity(r * cloud->xyz_mm[i].cast<double>() + t);
    const cv::Point px(int(std::lround(q.x())), int(std::lround(q.y())));
    STEREORIG_CHECK(px.inside(cv::Rect(cv::Point(0, 0), report->status.size())));
    uint8_t& st = report->status.at<uint8_t>(px);
    STEREORIG_CHECK(st == uint8_t(PixelStatus::kPoint));
    st = uint8_t(surface ? PixelStatus::kSeenThroughSurface : PixelStatus::kSeenThrough);
    const cv::Point lit_px = px - plan.roi.tl();
    if (lit_px.inside(cv::Rect(cv::Point(0, 0), report->lit.size())) && report->lit.at<uint8_t>(lit_px)) {
      --report->lit_filled;
      --report->lit_by_status[size_t(PixelStatus::kPoint)];
      ++report->lit_by_status[size_t(st)];
    }
  }
  RemovePoints(refuted, cloud, mesh);
  report->points = int(cloud->size());
}

}  // namespace

Eigen::Vector3d PointAhead(const Rig& rig, int m, double distance_mm) {
  // Module frame = left camera frame: left axis +z from 0; right axis R^T z
  // from the right camera's centre.
  const Pose left_from_right = rig.module(m).right_from_left.Inverse();
  const Eigen::Vector3d midpoint = 0.5 * left_from_right.translation_mm();
  const Eigen::Vector3d axis = (Eigen::Vector3d::UnitZ() + left_from_right.rotation().col(2)).normalized();
  return rig.S(0, m) * (midpoint + distance_mm * axis);
}

namespace {

// How to move the volume farther from module m's cameras. working_distance_mm
// moves it along module 0's axis: farther from a module that looks the same
// way, but nearer to one facing module 0 (a larger working_distance_mm on a
// facing rig made module 1's range worse), so the advice names the
// direction only where it holds.
std::string FartherAdvice(const Rig& rig, int m) {
  const Eigen::Vector3d axis0 = PointAhead(rig, 0, 1) - PointAhead(rig, 0, 0);
  const Eigen::Vector3d axis_m = PointAhead(rig, m, 1) - PointAhead(rig, m, 0);
  if (axis0.dot(axis_m) > 0) return "move it farther from the cameras (working_distance_mm, volume_center_mm)";
  return "move it farther from " + rig.module(m).name + "'s cameras, which face module 0's: volume_center_mm (a " +
         "larger working_distance_mm moves it away from module 0, nearer to " + rig.module(m).name + ")";
}

}  // namespace

Runtime::Runtime(const Rig& rig, const RuntimeOptions& options) : rig_(rig), options_(options) {
  options_.Check();
  // As many threads as the loops below can use at once: each module's row
  // loops, times the modules if they run in parallel.
  pool_ = WorkerPool(options_.match.num_threads * (options_.parallel_modules ? rig_.num_modules() : 1));
  volume_center_mm_ =
      options_.volume_center_mm ? *options_.volume_center_mm : PointAhead(rig_, 0, options_.working_distance_mm);
  const std::vector<Eigen::Vector3d> corners_ref = VolumeCorners(volume_center_mm_, options_.volume_size_mm);
  // The option that set the centre, named in the messages below with what
  // it was given: the one to change, not a list of both.
  const std::string volume_key = options_.volume_center_mm ? "volume_center_mm" : "working_distance_mm";
  char volume_value[160];
  if (options_.volume_center_mm)
    std::snprintf(volume_value, sizeof volume_value, "[%g, %g, %g]", options_.volume_center_mm->x(),
                  options_.volume_center_mm->y(), options_.volume_center_mm->z());
  else
    std::snprintf(volume_value, sizeof volume_value, "%g, ahead of module 0", options_.working_distance_mm);
  for (int m = 0; m < rig_.num_modules(); ++m) {
    const StereoModule& mod = rig_.module(m);
    const Camera& left = rig_.camera(mod.left_camera);
    const Camera& right = rig_.camera(mod.right_camera);
    if (right.imager_width_px() != left.imager_width_px() || right.imager_height_px() != left.imager_height_px())
      throw InputError(rig_.Where(), mod.name + ": its two cameras' imagers differ in size (not supported)");
    ModulePlan plan;
    plan.module = m;
    plan.reference_from_module = rig_.S(0, m);
    const Pose module_from_reference = rig_.S(m, 0);
    plan.camera_centre_reference_mm = plan.reference_from_module.translation_mm();
    // The volume is set in module 0's frame: for another module, a wrong
    // pose in the rig file can put it behind too.
    const std::string pose_check =
        m == 0 ? "" : mod.name + "'s pose in " + rig_.Where() + " (the volume is set in module 0's frame)";
    plan.geometry = ComputeRectification(
        left, right, mod.right_from_left, module_from_reference * volume_center_mm_,
        RectificationNames{rig_.Where(), options_.Where(), mod.name, pose_check, volume_key, volume_value});
    plan.maps = BuildRectifyMaps(plan.geometry, left, right);
    {  // the exact float tables, only for the masks (the runtime keeps the fixed-point ones)
      cv::Mat map_x, map_y;
      BuildRectifyMap(plan.geometry, right, RectifiedView::kRight, &map_x, &map_y);
      plan.right_valid = ViewValidMask(map_x, map_y, cv::Size(right.imager_width_px(), right.imager_height_px()));
      BuildRectifyMap(plan.geometry, left, RectifiedView::kLeft, &map_x, &map_y);
      plan.left_valid = ViewValidMask(map_x, map_y, cv::Size(left.imager_width_px(), left.imager_height_px()));
      plan.lit_window_on_data = LitWindowOnData(plan.left_valid);
    }
    // The volume's image: a box's central projection is bounded by its
    // corners' (all in front), and Z, so the disparity, is extreme at corners.
    double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9, d0 = 1e9, d1 = -1e9;
    for (const Eigen::Vector3d& c : corners_ref) {
      const Eigen::Vector3d p_rect = plan.geometry.rect_from_left * (module_from_reference * c);
      if (!(p_rect.z() > 1.0))
        throw InputError(options_.Where(), "the measurement volume reaches behind " + mod.name + "'s cameras: check " +
                                               volume_key + " / volume_size_mm" +
                                               (pose_check.empty() ? "" : ", or " + pose_check));
      const Eigen::Vector3d q = plan.geometry.PixelAndDisparity(p_rect);
      u0 = std::min(u0, q.x()), u1 = std::max(u1, q.x());
      v0 = std::min(v0, q.y()), v1 = std::max(v1, q.y());
      d0 = std::min(d0, q.z()), d1 = std::max(d1, q.z());
    }
    const cv::Rect image(0, 0, plan.geometry.size.width, plan.geometry.size.height);
    plan.roi = cv::Rect(cv::Point(int(std::floor(u0)), int(std::floor(v0))),
                        cv::Point(int(std::ceil(u1)) + 1, int(std::ceil(v1)) + 1)) &
               image;
    if (plan.roi.area() == 0)
      throw InputError(options_.Where(), "the measurement volume is not in " + mod.name + "'s view");
    plan.min_disparity_px = int(std::floor(d0)) - 2;
    plan.num_disparities = int(std::ceil(d1)) - int(std::floor(d0)) + 5;
    {  // What the matcher will be asked for, checked now rather than mid-capture on a module's thread.
      MatchOptions mo = options_.match;
      mo.min_disparity_px = plan.min_disparity_px;
      mo.num_disparities = plan.num_disparities;
      try {
        mo.Check();
      } catch (const InputError& e) {
        char range[96];
        std::snprintf(range, sizeof range, "disparities %d to %d px", plan.min_disparity_px,
                      plan.min_disparity_px + plan.num_disparities - 1);
        throw InputError(options_.Where(), "the measurement volume needs " + std::string(range) + " in " + mod.name +
                                               ", which the matcher cannot search (" + e.what() +
                                               "): make the volume shallower (volume_size_mm's depth) or " +
                                               FartherAdvice(rig_, m));
      }
    }
    plans_.push_back(std::move(plan));
  }
}

std::pair<cv::Mat, cv::Mat> Runtime::Rectify(const ModulePlan& plan, const std::vector<cv::Mat>& images) const {
  const StereoModule& mod = rig_.module(plan.module);
  // The rows of the ROI (plus the matcher's window margins), full width:
  // the right view needs columns left of the ROI.
  const cv::Size size = plan.geometry.size;
  const cv::Rect band(0, std::max(0, plan.roi.y - kWindowMarginPx), size.width,
                      std::min(size.height, plan.roi.y + plan.roi.height + kWindowMarginPx) -
                          std::max(0, plan.roi.y - kWindowMarginPx));
  cv::Mat left = cv::Mat::zeros(size, CV_8UC1), right = cv::Mat::zeros(size, CV_8UC1);
  cv::Mat l = left(band), r = right(band);
  cv::remap(images[mod.left_camera], l, plan.maps.left_fixed(band), plan.maps.left_frac(band), cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, 0);
  cv::remap(images[mod.right_camera], r, plan.maps.right_fixed(band), plan.maps.right_frac(band), cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, 0);
  return {left, right};
}

void Runtime::ProcessModule(const ModulePlan& plan, const std::vector<cv::Mat>& images, bool build_mesh,
                            PointCloud* cloud, Mesh* mesh, ModuleReport* report,
                            std::pair<cv::Mat, cv::Mat>* rectified) const {
  report->module = plan.module;
  report->left_camera = rig_.module(plan.module).left_camera;
  report->right_camera = rig_.module(plan.module).right_camera;
  auto t = Clock::now();
  const auto [left, right] = Rectify(plan, images);
  if (rectified) *rectified = {left, right};  // shared, not copied
  report->times_ms["rectify"] = MsSince(t);
  const cv::Size size = plan.geometry.size;
  const int margin = kWindowMarginPx;
  t = Clock::now();
  const cv::Mat lit_or_edge = LitMask(left(plan.roi), options_.lit_contrast_dn);
  // The grid-lit pixels the fill counts: not those whose window straddles
  // the step to the remap's zero fill (lit_mask.h). The crop keeps them, so
  // the match region (and every point) is as before; they only widened it
  // by a few columns where the lit region reaches the view's edge.
  cv::Mat lit;
  cv::bitwise_and(lit_or_edge, plan.lit_window_on_data(plan.roi), lit);
  cv::Rect match_roi = plan.roi;
  if (options_.crop_to_lit_region) {
    const cv::Rect box = cv::boundingRect(lit_or_edge);
    match_roi = box.area() > 0 ? cv::Rect(box.x + plan.roi.x - margin, box.y + plan.roi.y - margin,
                                          box.width + 2 * margin, box.height + 2 * margin) &
                                     plan.roi
                               : cv::Rect();
  }
  report->match_roi = match_roi;
  report->lit = lit;
  report->min_disparity_px = plan.min_disparity_px;
  report->num_disparities = plan.num_disparities;
  report->times_ms["lit_region"] = MsSince(t);

  t = Clock::now();
  MatchResult match;
  if (match_roi.area() > 0) {
    MatchOptions mo = options_.match;
    mo.roi = match_roi;
    mo.min_disparity_px = plan.min_disparity_px;
    mo.num_disparities = plan.num_disparities;
    mo.right_valid = plan.right_valid;
    mo.left_valid = plan.left_valid;
    match = Match(left, right, mo);
    for (const auto& [step, ms] : match.times_ms) report->times_ms["match." + step] = ms;
    report->surface_fit = match.surface_fit;
    report->row_drift = ReadRowDrift(match.vernier_readings);
    report->row_drift.warned = RowDriftWarned(report->row_drift, options_.match.line_index.max_row_offset_px);
    report->searched_min_disparity_px = match.searched_min_disparity_px;
    report->searched_num_disparities = match.searched_num_disparities;
    report->occupied_min_disparity_px = match.occupied_min_disparity_px;
    report->occupied_end_disparity_px = match.occupied_end_disparity_px;
  } else {
    match.disparity_px = cv::Mat(size, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
    match.confidence = cv::Mat(size, CV_32FC1, cv::Scalar(0));
    match.status = cv::Mat(size, CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kNotSearched)));
  }
  cv::Mat& status = report->status;
  status = match.status;
  report->times_ms["match"] = MsSince(t);

  // Triangulate into an organised grid of reference-frame points over the
  // match ROI (NaN = none), and the list of its points: the steps below
  // visit those only, row by row, as the cloud orders them.
  t = Clock::now();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const cv::Rect& r = match_roi;
  cv::Mat grid(r.size(), CV_32FC3, cv::Scalar(nan, nan, nan));  // grid(y - r.y, x - r.x)
  std::vector<cv::Point> kept;                                  // image pixels of grid's points, row-major
  const Eigen::Vector3d lo = volume_center_mm_ - 0.5 * options_.volume_size_mm;
  const Eigen::Vector3d hi = volume_center_mm_ + 0.5 * options_.volume_size_mm;
  const Eigen::Matrix3d r_ref = plan.reference_from_module.rotation();
  const Eigen::Vector3d t_ref = plan.reference_from_module.translation_mm();
  // Rows in parallel (each row's kept columns apart), then listed in row
  // order: the same list as one pass down the rows. The steps from here to
  // the cloud run last in the module, often while the other module is done
  // and its core free.
  std::vector<std::vector<int>> kept_x(size_t(r.height));
  ParallelForChunks(r.height, options_.match.num_threads, [&](int begin, int end) {
    for (int y = r.y + begin; y < r.y + end; ++y) {
      const float* d = match.disparity_px.ptr<float>(y);
      const float* c = match.confidence.ptr<float>(y);
      cv::Vec3f* g = grid.ptr<cv::Vec3f>(y - r.y);  // g[x - r.x]: no pointer before the row's start
      uint8_t* st = status.ptr<uint8_t>(y);
      std::vector<int>& row_kept = kept_x[size_t(y - r.y)];
      for (int x = r.x; x < r.x + r.width; ++x) {
        if (!std::isfinite(d[x])) continue;
        if (c[x] < options_.min_confidence) {
          st[x] = uint8_t(PixelStatus::kLowConfidence);
          continue;
        }
        const Eigen::Vector3d p = r_ref * plan.geometry.Triangulate(x, y, d[x]) + t_ref;
        if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) {  // range: the volume
          st[x] = uint8_t(PixelStatus::kOutsideVolume);
          continue;
        }
        g[x - r.x] = cv::Vec3f(float(p.x()), float(p.y()), float(p.z()));
        row_kept.push_back(x);
      }
    }
  });
  {
    size_t n = 0;
    for (const std::vector<int>& row : kept_x) n += row.size();
    kept.reserve(n);
    for (int yy = 0; yy < r.height; ++yy)
      for (int x : kept_x[size_t(yy)]) kept.emplace_back(x, r.y + yy);
  }
  auto grid_at = [&](const cv::Point& q) -> cv::Vec3f& { return grid.at<cv::Vec3f>(q.y - r.y, q.x - r.x); };
  // Object size: drop points farther than object_size_mm from the cloud's
  // per-axis median (background, gross mismatches).
  if (!kept.empty()) {
    std::vector<float> xs, ys, zs;
    xs.reserve(kept.size()), ys.reserve(kept.size()), zs.reserve(kept.size());
    for (const cv::Point& q : kept) {
      const cv::Vec3f& p = grid_at(q);
      xs.push_back(p[0]), ys.push_back(p[1]), zs.push_back(p[2]);
    }
    auto median = [](std::vector<float>& v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    const cv::Vec3f m(median(xs), median(ys), median(zs));
    const float limit2 = float(options_.object_size_mm * options_.object_size_mm);
    size_t n = 0;
    for (const cv::Point& q : kept) {
      cv::Vec3f& p = grid_at(q);
      if ((p - m).dot(p - m) > limit2) {
        p = cv::Vec3f(nan, nan, nan);
        status.at<uint8_t>(q) = uint8_t(PixelStatus::kObjectSize);
      } else {
        kept[n++] = q;
      }
    }
    kept.resize(n);
  }
  report->times_ms["triangulate"] = MsSince(t);

  // Normals from the depth grid (central differences +-step), oriented
  // towards the camera; the point's intensity and confidence; the index map
  // for the mesh (over the match ROI, -1 = no point).
  t = Clock::now();
  const int s = options_.normal_step_px;
  cv::Mat index(r.size(), CV_32SC1, cv::Scalar(-1));  // index(y - r.y, x - r.x)
  const Eigen::Vector3f eye = plan.camera_centre_reference_mm.cast<float>();
  auto at = [&](int x, int y) -> const cv::Vec3f* {  // image pixel (x, y); outside the match ROI: no point
    // One unsigned comparison per axis tests both ends (x < r.x wraps round).
    const unsigned gx = unsigned(x - r.x), gy = unsigned(y - r.y);
    if (gx >= unsigned(r.width) || gy >= unsigned(r.height)) return nullptr;
    const cv::Vec3f* p = grid.ptr<cv::Vec3f>(int(gy)) + gx;
    return std::isnan((*p)[0]) ? nullptr : p;
  };
  // Point k of `kept` is the cloud's point base + k, written by whichever
  // thread has it: the same cloud as one pass in order.
  const size_t base = cloud->size();
  cloud->Resize(base + kept.size());
  ParallelForChunks(int(kept.size()), options_.match.num_threads, [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      const int x = kept[size_t(k)].x, y = kept[size_t(k)].y;
      const cv::Vec3f* p = &grid_at(kept[size_t(k)]);
      // Widest available symmetric or one-sided difference in each direction.
      const cv::Vec3f *xa = at(x + s, y), *xb = at(x - s, y), *ya = at(x, y + s), *yb = at(x, y - s);
      Eigen::Vector3f n(0, 0, 0);
      if ((xa || xb) && (ya || yb)) {
        const cv::Vec3f dx = (xa ? *xa : *p) - (xb ? *xb : *p);
        const cv::Vec3f dy = (ya ? *ya : *p) - (yb ? *yb : *p);
        n = Eigen::Vector3f(dx[0], dx[1], dx[2]).cross(Eigen::Vector3f(dy[0], dy[1], dy[2]));
      }
      const Eigen::Vector3f pe((*p)[0], (*p)[1], (*p)[2]);
      if (n.norm() > 0) {
        n.normalize();
        if (n.dot(eye - pe) < 0) n = -n;
      } else {
        n = (eye - pe).normalized();  // isolated point: face the camera
      }
      const size_t i = base + size_t(k);
      index.at<int>(y - r.y, x - r.x) = int(i);
      cloud->xyz_mm[i] = pe;
      cloud->normal[i] = n;
      cloud->intensity[i] = left.at<uint8_t>(y, x);
      cloud->module[i] = uint8_t(plan.module);
      cloud->confidence[i] = match.confidence.at<float>(y, x);
    }
  });
  report->points = int(cloud->size());
  for (int y = 0; y < lit.rows; ++y) {
    const uint8_t* l = lit.ptr<uint8_t>(y);
    const int yi = y + plan.roi.y - r.y;  // index's row
    const int* in = yi >= 0 && yi < r.height ? index.ptr<int>(yi) : nullptr;
    const uint8_t* st = status.ptr<uint8_t>(y + plan.roi.y) + plan.roi.x;  // the lit mask's pixel x is st[x]
    for (int x = 0; x < lit.cols; ++x) {
      if (!l[x]) continue;
      ++report->lit_pixels;
      ++report->lit_by_status[st[x]];
      const int xi = x + plan.roi.x - r.x;
      report->lit_filled += in && unsigned(xi) < unsigned(r.width) && in[xi] >= 0;
    }
  }
  // An empty module's why (module_summary.h); a few ms, only then.
  if (report->lit_pixels == 0)
    report->camera_lit_pixels = cv::countNonZero(LitMask(images[report->left_camera], options_.lit_contrast_dn));
  if (report->points == 0)
    report->right_camera_lit_pixels = cv::countNonZero(LitMask(images[report->right_camera], options_.lit_contrast_dn));
  report->times_ms["normals"] = MsSince(t);

  if (!build_mesh) return;
  // Organised mesh: two triangles per 2x2 cell of points, unless an edge is
  // longer than mesh_max_edge_mm (a depth jump between surfaces). Vertex
  // order makes them counter-clockwise seen from the camera. Its vertices
  // are the cloud's points (indices into *cloud), not a copy of them.
  t = Clock::now();
  mesh->triangles.reserve(2 * kept.size());  // two per point inside a surface
  const float max_edge2 = float(options_.mesh_max_edge_mm * options_.mesh_max_edge_mm);
  auto short_edge = [&](int a, int b) { return (cloud->xyz_mm[a] - cloud->xyz_mm[b]).squaredNorm() <= max_edge2; };
  for (int y = 0; y + 1 < r.height; ++y) {
    const int* r0 = index.ptr<int>(y);
    const int* r1 = index.ptr<int>(y + 1);
    for (int x = 0; x + 1 < r.width; ++x) {
      const int a = r0[x], b = r0[x + 1], c = r1[x], d = r1[x + 1];
      if (a >= 0 && b >= 0 && c >= 0 && short_edge(a, b) && short_edge(a, c) && short_edge(b, c))
        mesh->triangles.emplace_back(a, c, b);
      if (b >= 0 && c >= 0 && d >= 0 && short_edge(b, d) && short_edge(c, d) && short_edge(b, c))
        mesh->triangles.emplace_back(b, c, d);
    }
  }
  report->times_ms["mesh"] = MsSince(t);
}

Reconstruction Runtime::Process(const std::vector<cv::Mat>& images, bool build_mesh) const {
  return pool_.Run([&] { return ProcessInPool(images, build_mesh); });
}

Reconstruction Runtime::ProcessInPool(const std::vector<cv::Mat>& images, bool build_mesh) const {
  if (int(images.size()) != rig_.num_cameras())
    throw InputError("capture", "has " + std::to_string(images.size()) + " images, the rig has " +
                                    std::to_string(rig_.num_cameras()) + " cameras");
  for (int k = 0; k < rig_.num_cameras(); ++k) {
    const Camera& cam = rig_.camera(k);
    if (images[k].type() != CV_8UC1)
      throw InputError("capture: cam" + std::to_string(k), "must be an 8-bit grey image");
    if (images[k].cols != cam.imager_width_px() || images[k].rows != cam.imager_height_px())
      throw InputError("capture: cam" + std::to_string(k), "is " + std::to_string(images[k].cols) + "x" +
                                                               std::to_string(images[k].rows) + ", the rig says " +
                                                               std::to_string(cam.imager_width_px()) + "x" +
                                                               std::to_string(cam.imager_height_px()));
  }
  const auto t_total = Clock::now();
  Reconstruction out;
  const int nm = int(plans_.size());
  std::vector<PointCloud> clouds(nm);
  std::vector<Mesh> meshes(nm);
  out.modules.resize(nm);
  // Each module's rectified pair, kept for the free-space test's photo check.
  const bool free_space = options_.free_space_test && nm > 1;
  std::vector<std::pair<cv::Mat, cv::Mat>> rectified(free_space ? nm : 0);
  auto t = Clock::now();
  // The modules in parallel on the pool, or all here in turn; an exception
  // in one reaches the caller once the others have stopped.
  ParallelForChunks(nm, options_.parallel_modules ? nm : 1, [&](int begin, int end) {
    for (int m = begin; m < end; ++m)
      ProcessModule(plans_[m], images, build_mesh, &clouds[m], &meshes[m], &out.modules[m],
                    free_space ? &rectified[m] : nullptr);
  });
  out.times_ms["modules"] = MsSince(t);
  if (free_space) {
    t = Clock::now();
    std::vector<FreeSpaceView> views(nm);
    for (int m = 0; m < nm; ++m)
      views[m] = FreeSpaceView{plans_[m].geometry, plans_[m].reference_from_module.Inverse(),
                               plans_[m].camera_centre_reference_mm, rectified[m].first, rectified[m].second};
    FreeSpaceOptions o = options_.free_space;
    o.surface_max_edge_mm = options_.mesh_max_edge_mm;  // a surface: what the mesh joins
    o.window = options_.match.subpixel;                 // the photo check: what the matcher would accept
    o.min_zncc = options_.match.min_zncc;
    const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, o);
    for (int m = 0; m < nm; ++m)
      if (std::any_of(refuted[m].begin(), refuted[m].end(), [](uint8_t v) { return v != 0; }))
        RemoveRefuted(plans_[m], refuted[m], &clouds[m], &meshes[m], &out.modules[m]);
    rectified.clear();
    out.times_ms["free_space"] = MsSince(t);
  }
  t = Clock::now();
  size_t total_points = 0;
  for (const PointCloud& c : clouds) total_points += c.size();
  out.cloud.Reserve(total_points);
  // Where each module's points begin in the merged cloud: its triangles'
  // offset in the joined mesh.
  std::vector<size_t> first_point(nm);
  for (int m = 0; m < nm; ++m) first_point[m] = out.cloud.size(), out.cloud.Append(clouds[m]), clouds[m] = PointCloud();
  out.times_ms["merge"] = MsSince(t);
  out.times_ms["total_point_cloud"] = MsSince(t_total);
  if (!build_mesh) return out;
  t = Clock::now();
  size_t total_triangles = 0;
  for (const Mesh& mesh : meshes) total_triangles += mesh.triangles.size();
  out.mesh.triangles.reserve(total_triangles);
  for (int m = 0; m < nm; ++m) out.mesh.Append(meshes[m], first_point[m]), meshes[m] = Mesh();
  out.times_ms["mesh_join"] = MsSince(t);
  t = Clock::now();
  if (options_.shape_model != ShapeModel::kNone) {
    const HoleFillResult fill = FillHolesFromModel(out.cloud, options_, &out.cloud, &out.mesh);
    out.filled_points = fill.added_points;
    out.shape_fit = fill.message;
  } else {
    out.shape_fit = "no shape model (shape_model: none)";
  }
  out.times_ms["hole_fill"] = MsSince(t);
  return out;
}

std::vector<std::string> CaptureImagePaths(const std::string& dir, const Rig& rig) {
  std::vector<std::string> paths;
  paths.reserve(size_t(rig.num_cameras()));
  for (int k = 0; k < rig.num_cameras(); ++k)
    paths.push_back((std::filesystem::path(dir) / CameraImageName(k)).string());
  return paths;
}

void CheckCaptureFiles(const std::string& dir, const Rig& rig) {
  namespace fs = std::filesystem;
  if (fs::exists(dir) && !fs::is_directory(dir)) throw InputError(dir, "is a file, not a capture folder");
  if (!fs::is_directory(dir)) throw InputError(dir, "capture folder not found");
  // Listed with an error code: std::filesystem's own exception read
  // "filesystem error: directory iterator cannot open directory: Permission
  // denied [DIR]", in no words of the command's.
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::optional<int> camera = CameraIndexOfImageName(it->path().filename().string());
    if (camera && *camera >= rig.num_cameras())
      throw InputError(it->path().string(), "the rig has only " + std::to_string(rig.num_cameras()) +
                                                " cameras: this capture does not match the rig");
  }
  if (ec) throw InputError(dir, "the capture folder cannot be read: " + ec.message());
  const std::vector<std::string> paths = CaptureImagePaths(dir, rig);
  for (size_t k = 0; k < paths.size(); ++k)
    if (!fs::exists(paths[k])) {
      // Every image from here on missing too: a capture of a rig with fewer
      // cameras (or the wrong rig file), said so; the camera's own line
      // read like a camera fault (the reverse case names the rig).
      bool rest_missing = k > 0;
      for (size_t j = k + 1; j < paths.size() && rest_missing; ++j) rest_missing = !fs::exists(paths[j]);
      throw InputError(paths[k], "missing camera image (camera " + std::to_string(k) + ")" +
                                     (rest_missing ? "; the capture holds cam0.png" +
                                                         (k > 1 ? " to " + CameraImageName(int(k) - 1) : "") +
                                                         " only and the rig has " + std::to_string(rig.num_cameras()) +
                                                         " cameras (" + std::to_string(rig.num_modules()) +
                                                         " modules): a capture of another rig, the wrong rig file, "
                                                         "or the last cameras not triggered"
                                                   : ""));
    } else if (fs::is_directory(paths[k]))
      throw InputError(paths[k], "is a folder, not camera " + std::to_string(k) + "'s image");
}

std::vector<cv::Mat> LoadCapture(const std::string& dir, const Rig& rig) {
  CheckCaptureFiles(dir, rig);
  const std::vector<std::string> paths = CaptureImagePaths(dir, rig);
  std::vector<cv::Mat> images;
  for (int k = 0; k < rig.num_cameras(); ++k) {
    // Its size checked from its header, before it is decoded.
    const Camera& cam = rig.camera(k);
    images.push_back(ReadGreyImage(paths[k], cv::Size(cam.imager_width_px(), cam.imager_height_px())));
  }
  return images;
}

RangeEnds ModuleReport::RangeEndsReached() const {
  return stereorig::RangeEndsReached(min_disparity_px, num_disparities, occupied_min_disparity_px,
                                     occupied_end_disparity_px);
}

}  // namespace stereorig
