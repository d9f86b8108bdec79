// Internal to the glTF import: the skinned node, and its skin's joints as points in the mesh's
// bind space, named after their nodes and linked to their nearest joint ancestor.
#pragma once

#include <vector>

#include "core/base/status.h"
#include "gltf_rig_skeleton.h"
#include "gltf_scene.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

// The one node with both a mesh and a skin (both in range). INVALID_ARGUMENT "no skin: ..." when
// there is none, and when there are several.
StatusOr<int> FindSkinnedNode(const tinygltf::Model& model);

// Skin `skin_index`'s joints (names, bind positions, parents; weights left empty). A joint's bind
// position is the translation of the inverse of its inverse bind matrix, or without
// inverseBindMatrices the translation of its node's world transform. Names are the nodes' names,
// "node<index>" for an unnamed node, "_2", "_3"... appended to repeats. INVALID_ARGUMENT for no
// joints, a joint that is no node or is listed twice, too few or singular inverse bind matrices.
StatusOr<std::vector<SkinJoint>> ReadSkinJoints(const tinygltf::Model& model, int skin_index,
                                                const SceneNodes& scene);

}  // namespace deform::gltf_internal
