#include "datasets/camera_rays.h"

#include <algorithm>
#include <thread>

namespace stereorig {

CameraRays::CameraRays(const Camera& camera, int threads)
    : width_(camera.imager_width_px()), height_(camera.imager_height_px()) {
  const size_t n = static_cast<size_t>(width_ + 1) * (height_ + 1);
  corners_.assign(n, Eigen::Vector3d::Zero());
  valid_.assign(n, 0);
  auto work = [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j) {
      for (int i = 0; i <= width_; ++i) {
        Eigen::Vector3d v;
        const size_t k = static_cast<size_t>(j) * (width_ + 1) + i;
        if (camera.Unproject(Eigen::Vector2d(i - 0.5, j - 0.5), &v) && v.allFinite()) {
          corners_[k] = v.normalized();
          valid_[k] = 1;
        }
      }
    }
  };
  const int rows = height_ + 1;
  threads = std::clamp(threads, 1, rows);  // a thread without a row is only a cost
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(work, rows * t / threads, rows * (t + 1) / threads);
  for (std::thread& t : pool) t.join();
}

}  // namespace stereorig
