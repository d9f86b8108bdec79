// Internal to the glTF import: the skinned node, and its skin's joints as points in the mesh's
// bind space, named after their nodes and linked to their nearest joint ancestor.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/base/status.h"
#include "gltf_rig_skeleton.h"
#include "gltf_scene.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

// Every node with both a mesh and a skin (both in range), ascending. INVALID_ARGUMENT "no skin:
// ..." when there is none, and for a node whose mesh or skin does not exist.
StatusOr<std::vector<int>> FindSkinnedNodes(const tinygltf::Model& model);

// A skin's joints: their nodes and bind matrices (each the inverse of its inverse bind matrix, or
// without inverseBindMatrices its node's world transform). INVALID_ARGUMENT for no joints, a
// joint that is no node or is listed twice, too few or singular inverse bind matrices.
struct SkinBinds {
  std::vector<int> joint_nodes;
  std::vector<Eigen::Matrix4d> bind;
};
StatusOr<SkinBinds> ReadSkinBinds(const tinygltf::Model& model, int skin_index,
                                  const SceneNodes& scene);

// The joints of `binds` (names, bind positions, parents; weights left empty). A joint's bind
// position is the translation of its bind matrix. Names are the nodes' names, "node<index>" for
// an unnamed node, "_2", "_3"... appended to repeats. A joint's parent is the nearest ancestor
// node that is also one of the joints.
std::vector<SkinJoint> SkinJointsOf(const tinygltf::Model& model, const SkinBinds& binds,
                                    const SceneNodes& scene);

}  // namespace deform::gltf_internal
