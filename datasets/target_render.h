// Rendering the double-sided calibration target, lasers off.
//
// The board is two printed planes (front and back faces, targets/target.h) of
// a plate; a camera sees the face its centre is in front of. The physical
// board may differ from the nominal target file: a print scale error, a
// misaligned back print, a bow. Pixels whose four corners fall on one colour
// take that colour; pixels that straddle a print edge are supersampled
// n x n (render.edge_samples_per_axis), each sample ray-cast through the lens.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "calib/core/camera.h"
#include "calib/core/pose.h"
#include "datasets/camera_rays.h"
#include "datasets/sim_spec.h"
#include "targets/target.h"

namespace stereorig {

// The physical board of one dataset.
struct PhysicalBoard {
  const Target* target = nullptr;  // nominal layout (what target.yaml says)
  Pose true_back_from_front;       // as built (may differ from the nominal by the misalignment knobs)
  double scale = 1.0;              // printed size / nominal size, about each face's first inner corner
  double bow_mm = 0.0;             // front face bulges towards its viewer by this much at the centre
  double white_albedo = 0.85;
  double black_albedo = 0.04;

  // The bow's displacement at face coordinates (x, y), mm: the front surface
  // sits at z = -Bow(x, y) in the front frame, the back one at z = +Bow(x, y)
  // in the back frame (the plate bends as one piece).
  double Bow(double x_mm, double y_mm) const;
  // A corner's true 3D position in its face frame, mm.
  Eigen::Vector3d TrueCorner(Face face, int id) const;
  // The same in the front face's frame (a back corner through the true
  // back_from_front): the board as one rigid body, the frame a capture's
  // board pose is given in.
  Eigen::Vector3d TrueCornerInFront(Face face, int id) const;
};

PhysicalBoard MakePhysicalBoard(const Target& target, const CalibrationSpec& spec);

// Which face a camera at world_from_cam sees of a board at world_from_front.
Face FaceSeen(const Pose& world_from_cam, const Pose& world_from_front);

// Radiance image (DN, CV_32F (H,W)) of the board seen by one camera.
cv::Mat RenderTargetRadiance(const CameraRays& rays, const Pose& world_from_cam, const Pose& world_from_front,
                             const PhysicalBoard& board, const RenderSpec& render);

// How many of the face's corners project inside the camera's image (true
// geometry, true lens).
int CornersInView(const Camera& camera, const Pose& world_from_cam, const Pose& world_from_front,
                  const PhysicalBoard& board);

}  // namespace stereorig
