// Turns a deformed frame back into a mesh file: the frame's positions with the mesh's triangles.
#pragma once

#include <string>

#include "core/base/status.h"
#include "core/geometry/mesh.h"

namespace deform::vr {

// Builds a mesh from `positions` (float32 little-endian xyz per vertex, as DeformFrame.positions)
// and `triangles` (uint32 little-endian, 3 per triangle, as GetMeshInfoResponse.triangles).
// INVALID_ARGUMENT when a buffer's size is not a whole number of records or a triangle names a
// missing vertex.
StatusOr<TriangleMesh> MeshFromBuffers(const std::string& positions, const std::string& triangles);

}  // namespace deform::vr
