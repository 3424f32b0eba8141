// Whether a file is a point cloud, told by its PLY header: what a batch asks
// before it removes an earlier run's mesh of a capture's name, since a
// capture named "x.mesh" has its cloud at x.mesh.ply, where capture x's PLY
// mesh would be (reconstruct_capture.h, AddEarlierMeshes).
#pragma once

#include <string>

namespace stereorig {

// True for a PLY file whose header declares a vertex element and no face
// element: a cloud (reconstruct/ply_io.h: EncodeCloudPly writes no face
// element; a mesh always has one, 0 faces included). False for a mesh, a
// file that is not PLY (an STL mesh), a header not ended within 4 KiB
// (stereorig's is ~300 bytes), or a file that cannot be read.
bool IsPlyCloudFile(const std::string& path);

}  // namespace stereorig
