// Export of one camera as an mrcal .cameramodel file, readable by mrcal's C
// reader and by python3-mrcal.
//
// mrcal's own C writer prints 6 decimals; this one prints %.17g, so the
// exported model projects exactly as ours does.
#pragma once

#include <string>

#include "camera.h"
#include "pose.h"

namespace stereorig {

// `cam_from_reference` becomes mrcal's `extrinsics` (rt_cam_ref: a rotation
// vector in radians, then a translation in mm).
std::string CameramodelText(const Camera& camera, const Pose& cam_from_reference);
void WriteCameramodel(const Camera& camera, const Pose& cam_from_reference, const std::string& path);

}  // namespace stereorig
