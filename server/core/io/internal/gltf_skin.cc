#include "gltf_skin.h"

#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "gltf_accessors.h"

namespace deform::gltf_internal {

using Normalization = AccessorSpec::IntegerNormalization;

StatusOr<std::vector<int>> FindSkinnedNodes(const tinygltf::Model& model) {
  std::vector<int> skinned;
  for (std::size_t n = 0; n < model.nodes.size(); ++n) {
    const tinygltf::Node& node = model.nodes[n];
    if (node.mesh < 0 || node.skin < 0) continue;
    if (static_cast<std::size_t>(node.mesh) >= model.meshes.size()) {
      return Status::InvalidArgument("node " + std::to_string(n) + " refers to mesh " +
                                     std::to_string(node.mesh) + ", which does not exist");
    }
    if (static_cast<std::size_t>(node.skin) >= model.skins.size()) {
      return Status::InvalidArgument("node " + std::to_string(n) + " refers to skin " +
                                     std::to_string(node.skin) + ", which does not exist");
    }
    skinned.push_back(static_cast<int>(n));
  }
  if (skinned.empty()) {
    return Status::InvalidArgument(
        "no skin: the glTF has no node with both a mesh and a skin (export the mesh with its "
        "armature / skin, and its skinning weights)");
  }
  return skinned;
}

StatusOr<SkinBinds> ReadSkinBinds(const tinygltf::Model& model, int skin_index,
                                  const SceneNodes& scene) {
  const tinygltf::Skin& skin = model.skins[static_cast<std::size_t>(skin_index)];
  const std::string where = "skin " + std::to_string(skin_index);
  if (skin.joints.empty()) return Status::InvalidArgument(where + " has no joints");
  std::set<int> listed;
  for (std::size_t j = 0; j < skin.joints.size(); ++j) {
    const int node = skin.joints[j];
    if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size()) {
      return Status::InvalidArgument(where + "'s joint " + std::to_string(j) + " is node " +
                                     std::to_string(node) + ", which does not exist");
    }
    if (!listed.insert(node).second) {
      return Status::InvalidArgument(where + " lists node " + std::to_string(node) + " twice");
    }
  }
  SkinBinds binds;
  binds.joint_nodes = skin.joints;
  binds.bind.resize(skin.joints.size());
  if (skin.inverseBindMatrices >= 0) {
    DEFORM_ASSIGN_OR_RETURN(const AccessorValues matrices,
                            ReadAccessor(model, skin.inverseBindMatrices,
                                         {"inverseBindMatrices of " + where,
                                          {TINYGLTF_TYPE_MAT4},
                                          {TINYGLTF_COMPONENT_TYPE_FLOAT},
                                          Normalization::kNever,
                                          std::numeric_limits<std::uint64_t>::max(),
                                          "matrices"}));
    if (matrices.count < static_cast<int>(skin.joints.size())) {
      return Status::InvalidArgument(where + " has " + std::to_string(matrices.count) +
                                     " inverse bind matrices for " +
                                     std::to_string(skin.joints.size()) + " joints");
    }
    for (std::size_t j = 0; j < skin.joints.size(); ++j) {
      Eigen::Matrix4d inverse_bind;
      for (int k = 0; k < 16; ++k) inverse_bind(k % 4, k / 4) = matrices.at(static_cast<int>(j), k);
      const Eigen::FullPivLU<Eigen::Matrix4d> lu(inverse_bind);
      const Eigen::Matrix4d bind =
          lu.isInvertible() ? Eigen::Matrix4d(lu.inverse()) : Eigen::Matrix4d::Zero();
      if (!lu.isInvertible() || !bind.allFinite()) {
        return Status::InvalidArgument(where + "'s inverse bind matrix " + std::to_string(j) +
                                       " is not invertible");
      }
      binds.bind[j] = bind;
    }
  } else {
    for (std::size_t j = 0; j < skin.joints.size(); ++j) {
      binds.bind[j] = scene.world[static_cast<std::size_t>(skin.joints[j])];
    }
  }
  return binds;
}

std::vector<SkinJoint> SkinJointsOf(const tinygltf::Model& model, const SkinBinds& binds,
                                    const SceneNodes& scene) {
  std::map<int, int> joint_of_node;
  for (std::size_t j = 0; j < binds.joint_nodes.size(); ++j) {
    joint_of_node.emplace(binds.joint_nodes[j], static_cast<int>(j));
  }
  std::vector<SkinJoint> joints(binds.joint_nodes.size());
  // Per node, the joint it is or the nearest one above it (-1: none), top-down.
  std::vector<int> joint_at_or_above(model.nodes.size(), -1);
  for (int node : scene.parents_first) {
    const auto it = joint_of_node.find(node);
    const int parent = scene.parent[static_cast<std::size_t>(node)];
    joint_at_or_above[static_cast<std::size_t>(node)] =
        it != joint_of_node.end() ? it->second
        : parent >= 0             ? joint_at_or_above[static_cast<std::size_t>(parent)]
                                  : -1;
  }
  std::set<std::string> names;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const int node = binds.joint_nodes[j];
    joints[j].position = binds.bind[j].block<3, 1>(0, 3);
    std::string name = model.nodes[static_cast<std::size_t>(node)].name;
    if (name.empty()) name = "node" + std::to_string(node);
    std::string unique = name;
    for (int k = 2; names.count(unique) != 0; ++k) unique = name + "_" + std::to_string(k);
    names.insert(unique);
    joints[j].name = unique;
    const int parent = scene.parent[static_cast<std::size_t>(node)];
    joints[j].parent = parent >= 0 ? joint_at_or_above[static_cast<std::size_t>(parent)] : -1;
  }
  return joints;
}

}  // namespace deform::gltf_internal
