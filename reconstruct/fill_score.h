// The fill rate against the simulator's truth, independent of the runtime's
// own image-based estimate of the grid-lit region.
//
// Issue 5's coverage figure: of the object pixels that both cameras of a
// module see and a laser grid lights, the share that ends with a point. The
// truth comes from the renderer's pixel-centre maps of every camera
// (truth/scenes/<scene>/{depth,id,lit}_camK.*, docs/simulator.md):
//   - object: the left camera's id map is non-zero;
//   - seen by the right camera: the left pixel's surface point (its depth,
//     unprojected through the TRUE left camera) projects into the true right
//     camera where that camera's depth map agrees (one of the 4 pixels
//     around the projection within depth_tolerance_mm): nothing occludes it;
//   - lit: the lit map is non-zero (inside a grid's envelope, facing the
//     projector, not in its shadow; the dark gaps between lines included).
// The fill is counted on the runtime's rectified left grid, where each pixel
// gives at most one point: a rectified pixel is a target if the original
// pixel it samples (nearest, through the runtime's rectification map) is.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "reconstruct/matcher.h"

namespace stereorig {

struct CameraTruthMaps {
  cv::Mat depth_mm;  // CV_32FC1 (H,W): z of the surface in the camera frame at the pixel centre, mm; 0 = none
  cv::Mat id;        // CV_8UC1 (H,W): object id; 0 = background
  cv::Mat lit;       // CV_8UC1 (H,W): bit k = lit by projector k; 0 = not lit
};

// Reads `dir`/{depth_camK.tiff, id_camK.png, lit_camK.png} for K < num_cameras.
// Throws InputError naming a file that is missing, cut short, damaged or of
// the wrong pixel type (read through reconstruct/image_file.h).
std::vector<CameraTruthMaps> ReadCameraTruthMaps(const std::string& dir, int num_cameras);

// CV_8UC1, the left camera's imager size: 255 on the pixels that count for
// module `module`'s fill (see above), else 0. `truth_rig`: the rig the maps
// were rendered with (truth/rig.yaml).
cv::Mat FillTargetMask(const Rig& truth_rig, int module, const CameraTruthMaps& left, const CameraTruthMaps& right,
                       double depth_tolerance_mm = 1.0);

struct FillFigures {
  int target_px = 0;  // rectified left pixels whose original pixel is a target
  int filled_px = 0;  // of those, pixels with a point
  int other_px = 0;   // points on non-target pixels (one camera only, unlit, background): not in the fill
  // Of the target pixels, how many ended with each PixelStatus (index =
  // the enum's value): where the fill is lost.
  std::vector<int> target_status = std::vector<int>(size_t(PixelStatus::kNumStatus), 0);
  double fill() const { return target_px ? double(filled_px) / target_px : 0.0; }
};

// status_rectified: CV_8UC1 on the module's rectified left grid, the
// PixelStatus of each pixel (ModuleReport::status); left_x, left_y: CV_32FC1 rectification map
// of the same size (rectified px -> original left px, RectifyMaps);
// target_original: FillTargetMask().
FillFigures ScoreFill(const cv::Mat& status_rectified, const cv::Mat& left_x, const cv::Mat& left_y,
                      const cv::Mat& target_original);

}  // namespace stereorig
