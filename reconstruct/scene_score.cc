#include "reconstruct/scene_score.h"

#include <filesystem>

#include "calib/core/rig_file.h"
#include "reconstruct/metrology/ply_points.h"

namespace stereorig {

SceneTruth ReadSceneTruth(const std::string& dataset_dir, const std::string& scene) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(dataset_dir) / "truth" / "scenes" / scene;
  const Rig truth_rig = ReadRigFile((fs::path(dataset_dir) / "truth" / "rig.yaml").string());
  SceneTruth t;
  t.name = scene;
  t.surface_mm = ReadPlyPoints((dir / "surface.ply").string());
  const std::vector<CameraTruthMaps> maps = ReadCameraTruthMaps(dir.string(), truth_rig.num_cameras());
  for (int m = 0; m < truth_rig.num_modules(); ++m) {
    const StereoModule& mod = truth_rig.module(m);
    t.fill_target.push_back(FillTargetMask(truth_rig, m, maps[mod.left_camera], maps[mod.right_camera]));
  }
  return t;
}

SceneScore ScoreScene(const Runtime& runtime, const Reconstruction& rec, const SceneTruth& truth) {
  SceneScore s;
  const int nm = int(runtime.plans().size());
  s.accuracy = ScoreAgainstTruth(rec.cloud, truth.surface_mm, nm);
  for (int m = 0; m < nm && m < int(truth.fill_target.size()); ++m) {
    // The exact float table (the runtime keeps only the fixed-point one).
    const ModulePlan& plan = runtime.plans()[m];
    cv::Mat left_x, left_y;
    BuildRectifyMap(plan.geometry, runtime.rig().camera(runtime.rig().module(plan.module).left_camera),
                    RectifiedView::kLeft, &left_x, &left_y);
    const FillFigures f = ScoreFill(rec.modules[m].status, left_x, left_y, truth.fill_target[m]);
    s.fill.push_back(f);
    s.fill_all.target_px += f.target_px;
    s.fill_all.filled_px += f.filled_px;
    s.fill_all.other_px += f.other_px;
    for (size_t k = 0; k < f.target_status.size(); ++k) s.fill_all.target_status[k] += f.target_status[k];
  }
  return s;
}

}  // namespace stereorig
