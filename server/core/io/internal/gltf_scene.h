// Internal to the glTF import: the node hierarchy, checked (children exist, one parent each, no
// cycles), and each node's world transform.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/base/status.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

struct SceneNodes {
  std::vector<int> parent;  // per node: its parent node, or -1
  // Per node: the product of the local transforms (matrix, or translation * rotation * scale)
  // from the root down to the node; model units (metres for glTF).
  std::vector<Eigen::Matrix4d> world;
  std::vector<int> parents_first;  // every node, each after its parent
};

// INVALID_ARGUMENT for a child index out of range, a node with two parents, a cycle, or a local
// transform that is malformed (matrix not 16 numbers, translation/scale not 3, rotation not 4, a
// zero or non-finite quaternion, non-finite values).
StatusOr<SceneNodes> ReadSceneNodes(const tinygltf::Model& model);

}  // namespace deform::gltf_internal
