#include "calib/check/board_scale.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <utility>

#include "calib/triangulation.h"

namespace stereorig {

std::vector<ModuleBoardScale> MeasureBoardScale(const Rig& rig, const Target& target,
                                                const std::vector<BoardObservation>& views, int min_corners) {
  // views by (capture, camera)
  std::map<std::pair<int, int>, const BoardObservation*> by_capture_camera;
  for (const BoardObservation& v : views) by_capture_camera[{v.capture, v.camera}] = &v;
  std::vector<ModuleBoardScale> out;
  for (int m = 0; m < rig.num_modules(); ++m) {
    const StereoModule& mod = rig.module(m);
    std::vector<double> scales;
    for (const auto& [key, left] : by_capture_camera) {
      if (key.second != mod.left_camera) continue;
      const auto right_it = by_capture_camera.find({key.first, mod.right_camera});
      if (right_it == by_capture_camera.end() || right_it->second->face != left->face) continue;
      const BoardObservation* right = right_it->second;
      std::map<int, Eigen::Vector2d> right_q;
      for (size_t i = 0; i < right->corner_ids.size(); ++i) right_q[right->corner_ids[i]] = right->q_px[i];
      std::vector<Eigen::Vector3d> nominal, measured;
      for (size_t i = 0; i < left->corner_ids.size(); ++i) {
        const auto r = right_q.find(left->corner_ids[i]);
        if (r == right_q.end()) continue;
        Eigen::Vector3d p;
        if (!TriangulatePair(rig.camera(mod.left_camera), rig.camera(mod.right_camera), mod.right_from_left,
                             left->q_px[i], r->second, &p))
          continue;
        nominal.push_back(target.CornerInFace(left->corner_ids[i]));
        measured.push_back(p);
      }
      if (static_cast<int>(nominal.size()) < min_corners) continue;
      Eigen::Matrix3Xd src(3, nominal.size()), dst(3, measured.size());
      for (size_t i = 0; i < nominal.size(); ++i) {
        src.col(i) = nominal[i];
        dst.col(i) = measured[i];
      }
      // A line of corners fixes no scale across it: the grid must span 2-D.
      const Eigen::Vector3d mean = src.rowwise().mean();
      const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(src.colwise() - mean);
      if (!(svd.singularValues()(1) > 1e-6 * svd.singularValues()(0))) continue;
      const Eigen::Matrix4d similarity = Eigen::umeyama(src, dst, true);
      scales.push_back(similarity.block<3, 1>(0, 0).norm());
    }
    if (scales.empty()) continue;
    const size_t mid = (scales.size() - 1) / 2;  // the lower median, as the check's other medians
    std::nth_element(scales.begin(), scales.begin() + mid, scales.end());
    out.push_back({m, scales[mid], static_cast<int>(scales.size())});
  }
  return out;
}

std::string BoardSizeNote(const std::vector<ModuleBoardScale>& scales, int num_modules, double square_size_mm) {
  if (num_modules < 2 || static_cast<int>(scales.size()) != num_modules) return "";
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ModuleBoardScale& m : scales) {
    if (m.captures < 3 || !(std::abs(m.scale - 1) > kMaxBoardScaleOff)) return "";
    lo = std::min(lo, m.scale - 1);
    hi = std::max(hi, m.scale - 1);
  }
  // Off the same way, and by the same within half the smaller.
  if (!(lo * hi > 0 && hi - lo <= 0.5 * std::min(std::abs(lo), std::abs(hi)))) return "";
  std::string each;
  for (const ModuleBoardScale& m : scales) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%smodule %d %+.2f%%", each.empty() ? "" : ", ", m.module, 100 * (m.scale - 1));
    each += buf;
  }
  char square[32];
  std::snprintf(square, sizeof square, "%.3f mm", square_size_mm);
  // The squares are those the check measured with: the target file's, or
  // the rig file's record of the board (check_target.h) where the two agree
  // within 0.5 %; so the note names the squares, not where they came from.
  return std::string("every module measures the board ") + (lo > 0 ? "larger" : "smaller") + " than squares of " +
         square + " (" + each + "): if these are not the board's squares, the figures are not the rig's";
}

}  // namespace stereorig
