// The RANSAC loop the shape fits share: draw hypotheses, score each by its
// inliers on an even subsample, keep the best.
#pragma once

#include <algorithm>
#include <functional>
#include <vector>

namespace stereorig {

// hypothesis(&model): draws one (false: degenerate draw, skipped).
// is_inlier(model, i): point i agrees with the model. Scores on every
// max(1, n / max_scoring_points)-th point. Returns the best model's inlier
// count scaled to all n points (0 if no hypothesis was drawn).
template <typename Model>
int RansacBest(int iterations, int n, int max_scoring_points, const std::function<bool(Model*)>& hypothesis,
               const std::function<bool(const Model&, int)>& is_inlier, Model* best) {
  const int step = std::max(1, n / max_scoring_points);
  int best_count = 0;
  for (int it = 0; it < iterations; ++it) {
    Model m;
    if (!hypothesis(&m)) continue;
    int count = 0;
    for (int k = 0; k < n; k += step) count += is_inlier(m, k);
    if (count > best_count) best_count = count, *best = m;
  }
  return best_count * step;
}

// The indices of the points that agree with `model`.
template <typename Model>
std::vector<int> Inliers(int n, const Model& model, const std::function<bool(const Model&, int)>& is_inlier) {
  std::vector<int> out;
  for (int k = 0; k < n; ++k)
    if (is_inlier(model, k)) out.push_back(k);
  return out;
}

}  // namespace stereorig
