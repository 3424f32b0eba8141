#include "reconstruct/fill_score.h"

#include <cmath>
#include <filesystem>

#include "calib/core/input_error.h"
#include "reconstruct/image_file.h"

namespace stereorig {

std::vector<CameraTruthMaps> ReadCameraTruthMaps(const std::string& dir, int num_cameras) {
  namespace fs = std::filesystem;
  // Through the checked reader, as every image input: a truth map missing,
  // cut short or damaged is named in one line, before libpng could print its
  // own (it used to read as an empty Mat, after "libpng error: Read Error").
  auto read = [&](const std::string& name, int type) {
    const std::string path = (fs::path(dir) / name).string();
    cv::Mat m = ReadImageFile(path);
    if (m.type() != type)
      throw InputError(path, "a truth map of the wrong pixel type (" + cv::typeToString(m.type()) + ", not " +
                                 cv::typeToString(type) + ")");
    return m;
  };
  std::vector<CameraTruthMaps> maps;
  for (int k = 0; k < num_cameras; ++k) {
    const std::string cam = "cam" + std::to_string(k);
    CameraTruthMaps t{read("depth_" + cam + ".tiff", CV_32FC1), read("id_" + cam + ".png", CV_8UC1),
                      read("lit_" + cam + ".png", CV_8UC1)};
    if (t.id.size() != t.depth_mm.size() || t.lit.size() != t.depth_mm.size())
      throw InputError(dir, cam + "'s truth maps differ in size");
    maps.push_back(std::move(t));
  }
  return maps;
}

cv::Mat FillTargetMask(const Rig& truth_rig, int module, const CameraTruthMaps& left, const CameraTruthMaps& right,
                       double depth_tolerance_mm) {
  const StereoModule& mod = truth_rig.module(module);
  const Camera& left_cam = truth_rig.camera(mod.left_camera);
  const Camera& right_cam = truth_rig.camera(mod.right_camera);
  STEREORIG_CHECK(left.depth_mm.cols == left_cam.imager_width_px() &&
                  left.depth_mm.rows == left_cam.imager_height_px());
  STEREORIG_CHECK(right.depth_mm.cols == right_cam.imager_width_px() &&
                  right.depth_mm.rows == right_cam.imager_height_px());
  cv::Mat target(left.depth_mm.size(), CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < target.rows; ++r) {
    const float* z = left.depth_mm.ptr<float>(r);
    const uint8_t* id = left.id.ptr<uint8_t>(r);
    const uint8_t* lit = left.lit.ptr<uint8_t>(r);
    std::vector<int> cols;
    for (int c = 0; c < target.cols; ++c)
      if (id[c] && lit[c] && z[c] > 0) cols.push_back(c);
    if (cols.empty()) continue;
    Eigen::Matrix<double, Eigen::Dynamic, 2> q(cols.size(), 2);
    for (size_t i = 0; i < cols.size(); ++i) q.row(i) << cols[i], r;
    const Eigen::Matrix<double, Eigen::Dynamic, 3> v = left_cam.UnprojectMany(q);
    Eigen::Matrix<double, Eigen::Dynamic, 3> p_right(cols.size(), 3);
    for (size_t i = 0; i < cols.size(); ++i) {
      const Eigen::Vector3d vi = v.row(i).transpose();
      const Eigen::Vector3d p_left = vi * (z[cols[i]] / vi.z());
      p_right.row(i) = (mod.right_from_left * p_left).transpose();
    }
    const Eigen::Matrix<double, Eigen::Dynamic, 2> q_right = right_cam.ProjectMany(p_right);
    uint8_t* out = target.ptr<uint8_t>(r);
    for (size_t i = 0; i < cols.size(); ++i) {
      if (!v.row(i).allFinite() || !q_right.row(i).allFinite() || !(p_right(i, 2) > 0)) continue;
      // The 4 right pixels around the projection (pixel centres at integers).
      const int x0 = int(std::floor(q_right(i, 0))), y0 = int(std::floor(q_right(i, 1)));
      bool seen = false;
      for (int dy = 0; dy < 2 && !seen; ++dy)
        for (int dx = 0; dx < 2 && !seen; ++dx) {
          const int x = x0 + dx, y = y0 + dy;
          if (x < 0 || y < 0 || x >= right.depth_mm.cols || y >= right.depth_mm.rows) continue;
          const float zr = right.depth_mm.at<float>(y, x);
          seen = zr > 0 && std::abs(zr - p_right(i, 2)) <= depth_tolerance_mm;
        }
      if (seen) out[cols[i]] = 255;
    }
  }
  return target;
}

FillFigures ScoreFill(const cv::Mat& status_rectified, const cv::Mat& left_x, const cv::Mat& left_y,
                      const cv::Mat& target_original) {
  STEREORIG_CHECK(status_rectified.type() == CV_8UC1 && left_x.type() == CV_32FC1 && left_y.type() == CV_32FC1);
  STEREORIG_CHECK(status_rectified.size() == left_x.size() && left_x.size() == left_y.size());
  FillFigures f;
  for (int y = 0; y < status_rectified.rows; ++y) {
    const uint8_t* status = status_rectified.ptr<uint8_t>(y);
    const float* mx = left_x.ptr<float>(y);
    const float* my = left_y.ptr<float>(y);
    for (int x = 0; x < status_rectified.cols; ++x) {
      const long c = std::lround(mx[x]), r = std::lround(my[x]);
      const bool target = c >= 0 && r >= 0 && c < target_original.cols && r < target_original.rows &&
                          target_original.at<uint8_t>(int(r), int(c));
      const bool point = status[x] == uint8_t(PixelStatus::kPoint);
      if (target) {
        ++f.target_px;
        f.filled_px += point;
        if (status[x] < f.target_status.size()) ++f.target_status[status[x]];
      } else {
        f.other_px += point;
      }
    }
  }
  return f;
}

}  // namespace stereorig
