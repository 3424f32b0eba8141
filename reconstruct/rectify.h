// Rectification of one stereo module, for verged cameras and any mrcal lens
// model.
//
// The rectified frame shares the left camera's centre; its x axis runs along
// the baseline (left -> right camera centre), its z axis is the mean of the
// two optical axes made orthogonal to x. Both rectified cameras are pinholes
// with the same focal length and rows; the right one's principal point is
// moved by `disparity_offset_px` so that a verged pair keeps the object near
// the same columns in both images (without it the verging would push the
// right view ~fB/Z px off the image). A point at depth Z (rectified frame)
// then has image disparity
//   d_img = x_left - x_right = f * B / Z - disparity_offset_px.
// The remap tables are built by projecting each rectified pixel's ray through
// Camera::Project (mrcal), so no OpenCV distortion model is assumed.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>

#include "calib/core/rig.h"

namespace stereorig {

struct RectifiedGeometry {
  Eigen::Matrix3d rect_from_left = Eigen::Matrix3d::Identity();   // rotation: rectified frame from left camera
  Eigen::Matrix3d right_from_rect = Eigen::Matrix3d::Identity();  // rotation: right camera from rectified frame
  double focal_px = 0;                                            // both rectified cameras
  double cx_left_px = 0, cy_px = 0;
  double disparity_offset_px = 0;  // cx_right = cx_left + offset
  double baseline_mm = 0;          // |left -> right camera centre|
  cv::Size size;                   // rectified image size, px

  // Rectified-frame point (mm) -> left rectified pixel and image disparity.
  Eigen::Vector3d PixelAndDisparity(const Eigen::Vector3d& p_rect) const;
  // (u, v, d_img) -> point in the LEFT CAMERA (= module) frame, mm.
  Eigen::Vector3d Triangulate(double u_px, double v_px, double d_img_px) const;
};

// Builds the geometry. `look_at_left_mm` (left camera frame) is a point that
// should sit at the centre of both rectified images (the measurement
// volume's centre): it fixes the principal points and the disparity offset.
// The focal length is the smaller mean focal length of the two cameras, so
// no view is magnified beyond its native sampling.
// Throws InputError on a degenerate module (zero baseline, baseline along
// the optical axes: where `names.rig`) or a look-at point not in front of it
// (behind the plane through its cameras' centres that the rectified views
// look away from, so beside them too: where `names.options`, the angle off
// the module's viewing direction said); the messages name the module as
// `names.module`.
struct RectificationNames {
  std::string rig = "rig";                  // the rig file
  std::string options = "runtime options";  // where the measurement volume was set
  std::string module = "a module";          // the module's name, e.g. "module0"
  // What else to check when the volume is behind the module, appended as
  // "or ...": for a module other than the reference one, its pose in the
  // rig file (the volume is set in the reference frame). Empty: nothing.
  std::string also_check;
  // The option that put the volume's centre where it is, and its value as
  // the message gives it ("volume_center_mm", "[5000, 0, 200]").
  std::string volume_key = "volume_center_mm / working_distance_mm";
  std::string volume_value;
};
RectifiedGeometry ComputeRectification(const Camera& left, const Camera& right, const Pose& right_from_left,
                                       const Eigen::Vector3d& look_at_left_mm, const RectificationNames& names = {});

// Remap table of one view (CV_32FC1 x and y, rectified size): rectified
// pixel -> original pixel. Pixels whose ray does not project (behind a lens)
// get -1 (outside the image, so remap fills them with 0).
enum class RectifiedView { kLeft, kRight };
void BuildRectifyMap(const RectifiedGeometry& g, const Camera& cam, RectifiedView view, cv::Mat* map_x, cv::Mat* map_y);

// Both views' tables in cv::convertMaps fixed point (CV_16SC2 + CV_16UC1, the
// fast cv::remap form, 1/32 px), the form the runtime keeps: 6 bytes a pixel
// instead of the float tables' 8 (the float ones are rebuilt where exact
// values are needed, e.g. scoring).
struct RectifyMaps {
  cv::Mat left_fixed, left_frac, right_fixed, right_frac;
};
RectifyMaps BuildRectifyMaps(const RectifiedGeometry& g, const Camera& left, const Camera& right);

}  // namespace stereorig
