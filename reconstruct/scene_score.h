// Scoring the runtime on one of the simulator's scenes against its truth:
// accuracy (score.h: one rigid alignment, then distances to the dense truth
// surface) and the fill of every module (fill_score.h: object pixels both
// cameras see and a grid lights). Used by `stereorig score`, the runtime's
// end-to-end test, and anything else that judges the runtime on a dataset.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "calib/core/rig.h"
#include "reconstruct/fill_score.h"
#include "reconstruct/runtime.h"
#include "reconstruct/score.h"

namespace stereorig {

struct SceneTruth {
  std::string name;
  std::vector<Eigen::Vector3d> surface_mm;  // (N) dense samples, truth reference frame (module 0)
  std::vector<cv::Mat> fill_target;         // per module: FillTargetMask() on its left camera's imager
};

// Reads DATASET/truth/scenes/<scene>/ (surface.ply and the per-camera maps)
// and builds each module's fill target with the TRUE rig (truth/rig.yaml).
// Throws InputError naming a missing or bad file.
SceneTruth ReadSceneTruth(const std::string& dataset_dir, const std::string& scene);

struct SceneScore {
  CloudScore accuracy;            // merged and per module
  std::vector<FillFigures> fill;  // per module
  FillFigures fill_all;           // summed over modules
};

// `runtime`: the one that made `rec` (its rectification maps place the
// points on the original pixels).
SceneScore ScoreScene(const Runtime& runtime, const Reconstruction& rec, const SceneTruth& truth);

}  // namespace stereorig
