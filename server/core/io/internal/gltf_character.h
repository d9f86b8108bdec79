// Internal to the glTF import: every skinned mesh node of the scene as one skinned mesh over one
// joint list (the union of their skins' joints, by node), in node order.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "gltf_rig_skeleton.h"
#include "gltf_scene.h"
#include "gltf_skinned_mesh.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

// The file vertices one skinned mesh node contributes: [first_vertex, first_vertex + count).
struct SkinnedNodeVertices {
  int node = -1;
  int first_vertex = 0;
  int num_vertices = 0;
};

struct CharacterMesh {
  // The nodes' meshes concatenated in node-index order; "bones" of joint_weights index `joints`.
  FileMesh file;
  // The union of the skins' joints: the first skinned node's skin's joints in its order, then each
  // later skin's joints not yet listed. Bind positions from the first skin that lists the joint.
  std::vector<SkinJoint> joints;
  // Per joint: its node, and its bind matrix in the unified bind space (joint space to the mesh's
  // space in the bind pose): what places a mesh node parented to the joint in the mesh's space.
  std::vector<int> joint_nodes;
  std::vector<Eigen::Matrix4d> joint_bind;
  std::vector<SkinnedNodeVertices> nodes;  // one per skinned mesh node, in node order
};

// Every node with both a mesh and a skin (in range). A node whose skin places the shared joints
// differently from the first skin by one rigid or affine transform (inverse bind matrices of a
// mesh exported in another bind space) has its positions mapped into the first skin's bind space
// by that transform; skins that disagree otherwise are INVALID_ARGUMENT naming the nodes and the
// joint. INVALID_ARGUMENT "no skin: ..." when no node is skinned; RESOURCE_EXHAUSTED when the
// concatenated mesh exceeds `limits`.
StatusOr<CharacterMesh> ReadCharacterMesh(const tinygltf::Model& model, const SceneNodes& scene,
                                          const MeshLimits& limits);

}  // namespace deform::gltf_internal
