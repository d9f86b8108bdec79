// Internal to the glTF import: the skinned mesh's primitives, concatenated in file order as an
// engine holds them (positions, triangles and per-vertex joint influences), each read through
// checked accessors.
#pragma once

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skin_weights.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

struct FileMesh {
  Positions positions;  // #file vertices by 3, as the file holds them (floats)
  Triangles triangles;  // indices into positions
  // Per file vertex, its influences with non-zero weight: "bones" are the skin's joint indices
  // (JOINTS_n values), weights as read (WEIGHTS_n, normalized integers mapped to [0, 1]), not
  // normalized per vertex.
  SkinWeights joint_weights;
};

// Reads mesh `mesh_index` (in range) of `model`, skinned by a skin of `num_joints` joints.
// INVALID_ARGUMENT for a primitive that is not triangles (mode 4) or lacks POSITION, JOINTS_0 or
// WEIGHTS_0, a JOINTS_n without its WEIGHTS_n (or the reverse), a joint index beyond the skin, a
// negative weight, an index beyond its primitive's vertices, a corner count that is not a multiple
// of 3, and any accessor problem (gltf_accessors.h). RESOURCE_EXHAUSTED beyond limits (file
// vertices, triangles).
StatusOr<FileMesh> ReadSkinnedMesh(const tinygltf::Model& model, int mesh_index, int num_joints,
                                   const MeshLimits& limits);

// Mesh `mesh_index` (in range) without a skin: positions and triangles as ReadSkinnedMesh reads
// them, no influences (joint_weights empty). The same errors but those of influences.
StatusOr<FileMesh> ReadStaticMesh(const tinygltf::Model& model, int mesh_index,
                                  const MeshLimits& limits);

}  // namespace deform::gltf_internal
