// `stereorig reconstruct --rectified-out DIR`: each module's rectified pair
// as the runtime matches it, for `stereorig match`, which takes a rectified
// pair and a disparity range and nothing of the rig. Without it a user
// tuning the matcher had no way to get either: the pair is the runtime's
// rectification of one capture, the range the one it derives from the
// measurement volume (ModulePlan), neither of which the rig file says.
#pragma once

#include <string>
#include <vector>

#include "calib/core/atomic_file.h"
#include "reconstruct/runtime.h"

namespace stereorig {

struct RectifiedPairPaths {
  std::string left, right;  // DIR/module<M>_left.png, DIR/module<M>_right.png
  std::string disparity;    // DIR/module<M>_disparity.pfm: where the printed match command writes
};

// The files of each of the rig's `num_modules` modules in `dir`, in module order.
std::vector<RectifiedPairPaths> RectifiedPairPathsIn(const std::string& dir, int num_modules);

// Adds each module's rectified pair (Runtime::Rectify: 8-bit grey PNGs of the
// rectified size, the rows of the volume's ROI and the matcher's window
// margins, the rest 0) to `written`, so that they are written with the
// command's other outputs, all or none.
void AddRectifiedPairs(const Runtime& runtime, const std::vector<cv::Mat>& images,
                       const std::vector<RectifiedPairPaths>& paths, AtomicOutputSet* written);

// One line for a module: where its pair went and the `stereorig match`
// command that searches it as the runtime does: the volume's disparity
// range and ROI (ModulePlan; before the lit-region crop and the band pass,
// and with match's own defaults, not the runtime options' match: keys).
std::string RectifiedPairLine(const ModulePlan& plan, const RectifiedPairPaths& paths);

}  // namespace stereorig
