// The one-shot reconstruction runtime: built once from a rig and runtime
// options, then Process() turns one capture (one image per camera) into a
// point cloud in the reference frame, and optionally a mesh.
//
// Built once (constructor): per module, the rectification (rectify.h) and its
// remap tables, the disparity search range and the region of interest, both
// derived from the measurement volume. Process() is const: it keeps no state
// between captures and may be called from several threads at once. Modules
// run on their own threads.
//
// Per module: rectify -> crop to the lit region -> match (matcher.h: census
// SGM, filters, sub-pixel, what the right camera cannot see) -> triangulate to mm -> range filters (volume,
// object size) -> intensity, confidence -> normals from the depth grid ->
// organised mesh. Then: concatenation through S into the reference frame,
// the joined mesh, and hole filling from a fitted shape model.
#pragma once

#include <array>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "reconstruct/disparity_band.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/point_cloud.h"
#include "reconstruct/rectify.h"
#include "reconstruct/row_drift.h"
#include "reconstruct/runtime_options.h"

namespace stereorig {

// The rows rectified above and below a module's ROI, and the margin added
// around the lit region it crops to: the matcher's windows reach this far.
inline constexpr int kWindowMarginPx = 8;

// What the runtime precomputes for one module.
struct ModulePlan {
  int module = 0;
  RectifiedGeometry geometry;
  RectifyMaps maps;
  cv::Mat right_valid;         // CV_8UC1: rectified right px with sensor data (right_occlusion.h)
  cv::Mat left_valid;          // CV_8UC1: rectified left px with sensor data (left_view_edge.h)
  cv::Mat lit_window_on_data;  // CV_8UC1: left px whose lit-mask window is all sensor data (lit_mask.h)
  cv::Rect roi;                // rectified left px covered by the measurement volume
  int min_disparity_px = 0;    // image disparity range of the volume (rectify.h), with 2 px margin
  int num_disparities = 0;
  Pose reference_from_module;                  // S[0][module]
  Eigen::Vector3d camera_centre_reference_mm;  // the module's left camera centre
};

struct ModuleReport {
  int module = 0;
  cv::Rect match_roi;                             // after cropping to the lit region
  int min_disparity_px = 0, num_disparities = 0;  // the volume's range, [min, min + num) px
  // What the matcher searched at full resolution (MatchResult): the occupied
  // band within that range; 0 / 0 when nothing was matched (no lit region).
  int searched_min_disparity_px = 0, searched_num_disparities = 0;
  // The band pass's kept bins before its margin (MatchResult): [min, end)
  // px; end <= min where it found none.
  int occupied_min_disparity_px = 0, occupied_end_disparity_px = 0;
  // Which ends of the volume's range those bins reach, within one bin
  // (kBandBinPx: matches within two bins, 8 px, of the end); near = the
  // largest disparities. Reached, the surface may go on past the volume, or
  // the grid was matched a whole number of periods off, a copy of itself
  // inside the range (the grid's turn makes it repeat every ~22 periods
  // along a row), its points where nothing is. Measured on the demo's five
  // scenes (calibrated rig): under the default volume every module's bins
  // keep 49-153 px from either end; with the volume moved in front of the
  // objects (`volume_center_mm: [0, 0, 130]`, 40 mm deep) or to 120 mm
  // (`working_distance_mm: 120`), every scene with points has a module
  // reaching an end, though not every module with wrong points does (the
  // front plate's module 0: 25 px). Against the truth (`score --diagnose`):
  // the front cup's module 0 all 185 px off, the 120 mm cup's module 1 95 %
  // more than 2 mm off. Neither end without a band.
  using RangeEnds = stereorig::RangeEnds;  // disparity_band.h
  RangeEnds RangeEndsReached() const;
  int points = 0;                // points kept
  int seen_through = 0;          // of the module's points, those the free-space test removed (free_space.h)
  int seen_through_surface = 0;  // of those, the ones nothing hid: removed with their surface, mostly seen through
  int lit_pixels = 0;            // grid-lit pixels of the rectified left image in the volume's ROI
  int lit_filled = 0;            // of those, pixels with a kept point
  // Only when lit_pixels is 0 (else -1): the grid-lit pixels of the left
  // camera's whole image, unrectified. Tells a volume beside what the grid
  // lights (> 0) from a capture it lights nowhere (0: dark, no grid).
  int camera_lit_pixels = -1;
  // Only when the module kept no point (else -1): the grid-lit pixels of the
  // right camera's whole image, unrectified. 0 while the left is lit: the
  // right camera saw no grid (not triggered, a dark or flat image), so no
  // search could match, wherever the volume is.
  int right_camera_lit_pixels = -1;
  int left_camera = -1, right_camera = -1;  // the module's cameras (Rig indices: capture images camK.png)
  // The lit pixels by their final PixelStatus (disparity_state.h): kPoint
  // counts lit_filled, the others name the test that refused the rest. The
  // runtime's own account of where fill goes, with no truth needed.
  std::array<int, size_t(PixelStatus::kNumStatus)> lit_by_status{};
  double fill_rate() const { return lit_pixels ? double(lit_filled) / lit_pixels : 0.0; }
  // CV_8UC1, the module's rectified left image size: the PixelStatus
  // (matcher.h) of each pixel: kPoint where a point was kept, else the test
  // that dropped it (for scoring the fill against truth and finding where it
  // is lost, reconstruct/fill_score.h).
  cv::Mat status;
  // CV_8UC1 over the volume's ROI (ModulePlan::roi): the grid-lit pixels
  // lit_pixels counts (for recounting after the free-space test).
  cv::Mat lit;
  std::map<std::string, double> times_ms;        // rectify, lit_region, match, triangulate, normals, mesh
  std::optional<SurfaceFitSummary> surface_fit;  // the matcher's (matcher.h), if the fit ran
  // How far the module's rectified rows read off at the laser grid's
  // vernier (row_drift.h); not read without the line index (passive).
  RowDrift row_drift;
};

struct Reconstruction {
  PointCloud cloud;  // all modules, then filled points; reference frame
  Mesh mesh;         // over cloud's points (filled ones too); empty unless requested
  std::vector<ModuleReport> modules;
  std::map<std::string, double> times_ms;  // modules (wall), free_space, merge, mesh_join, hole_fill, total_point_cloud
  int filled_points = 0;                   // points added by hole filling
  std::string shape_fit;                   // one line: the fitted model, or why there is none
};

class Runtime {
 public:
  // Throws InputError if the options are bad or the volume is not in front
  // of every module.
  Runtime(const Rig& rig, const RuntimeOptions& options);

  const Rig& rig() const { return rig_; }
  const RuntimeOptions& options() const { return options_; }
  const std::vector<ModulePlan>& plans() const { return plans_; }
  // The measurement volume's centre in the reference frame (module 0), mm:
  // volume_center_mm, or working_distance_mm ahead of module 0.
  const Eigen::Vector3d& volume_center_mm() const { return volume_center_mm_; }

  // images[k]: camera k's 8-bit grey image (global camera index), each the
  // size the rig says. `build_mesh` adds the organised meshes, the joined
  // mesh and the model fill (timed separately). Throws InputError on images
  // of the wrong number, type or size.
  // Runs on the runtime's worker pool: at most match.num_threads threads
  // per module, times the modules if parallel_modules (parallel_for.h).
  Reconstruction Process(const std::vector<cv::Mat>& images, bool build_mesh) const;

  // A module's rectified pair (left, right; CV_8UC1, the rectified size):
  // the rows of its ROI and kWindowMarginPx above and below, full width,
  // the rest 0. ProcessModule's first step; `stereorig tune` measures the
  // grid in the left one.
  std::pair<cv::Mat, cv::Mat> Rectify(const ModulePlan& plan, const std::vector<cv::Mat>& images) const;

  // The per-module work of Process(), exposed for tests: the module's cloud
  // (reference frame) and its organised mesh over it (if build_mesh); and, if
  // `rectified` is given, the rectified pair it matched (left, right).
  void ProcessModule(const ModulePlan& plan, const std::vector<cv::Mat>& images, bool build_mesh, PointCloud* cloud,
                     Mesh* mesh, ModuleReport* report, std::pair<cv::Mat, cv::Mat>* rectified = nullptr) const;

 private:
  // Process()'s work, run inside pool_ (its loops take pool_'s threads).
  Reconstruction ProcessInPool(const std::vector<cv::Mat>& images, bool build_mesh) const;

  Rig rig_;
  RuntimeOptions options_;
  Eigen::Vector3d volume_center_mm_;
  std::vector<ModulePlan> plans_;
  WorkerPool pool_;
};

// The files LoadCapture reads from capture folder DIR: DIR/camK.png for
// every camera K of the rig, in camera order (a command protects them from
// its outputs, apps/output_paths.h).
std::vector<std::string> CaptureImagePaths(const std::string& dir, const Rig& rig);

// The checks of LoadCapture that need no decoding: DIR is a folder holding
// camK.png for every camera K of the rig and none beyond them (a capture made
// with another rig). Throws InputError naming the folder or file. Cheap, so a
// batch checks all its captures before it writes anything.
void CheckCaptureFiles(const std::string& dir, const Rig& rig);

// Loads a capture folder: DIR/camK.png for every camera K of the rig, 8-bit
// grey, the rig's imager size. Throws InputError naming the file on a
// missing camera, a wrong size or type (from a PNG's header, before it is
// decoded: grey_image.h), or a camK.png beyond the rig's cameras
// (CheckCaptureFiles).
std::vector<cv::Mat> LoadCapture(const std::string& dir, const Rig& rig);

// The point `distance_mm` in front of module `m`'s baseline midpoint along
// the mean of its two optical axes, in the reference frame.
Eigen::Vector3d PointAhead(const Rig& rig, int module, double distance_mm);

}  // namespace stereorig
