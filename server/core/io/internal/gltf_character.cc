#include "gltf_character.h"

#include <Eigen/LU>
#include <map>
#include <string>
#include <vector>

#include "gltf_skin.h"

namespace deform::gltf_internal {
namespace {

// Two bind spaces agree on a joint when their transforms differ by less than this (relative to
// the transform's size): float inverse bind matrices of one export.
constexpr double kBindSpaceTolerance = 1e-4;

}  // namespace

StatusOr<CharacterMesh> ReadCharacterMesh(const tinygltf::Model& model, const SceneNodes& scene,
                                          const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const std::vector<int> skinned, FindSkinnedNodes(model));
  CharacterMesh character;
  SkinBinds unified;
  std::map<int, int> unified_of_node;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> triangles;
  for (const int node_index : skinned) {
    const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(node_index)];
    DEFORM_ASSIGN_OR_RETURN(const SkinBinds binds, ReadSkinBinds(model, node.skin, scene));
    std::vector<int> to_unified(binds.joint_nodes.size());
    for (std::size_t j = 0; j < binds.joint_nodes.size(); ++j) {
      const auto [it, added] = unified_of_node.emplace(
          binds.joint_nodes[j], static_cast<int>(unified.joint_nodes.size()));
      if (added) {
        unified.joint_nodes.push_back(binds.joint_nodes[j]);
        unified.bind.push_back(binds.bind[j]);
      }
      to_unified[j] = it->second;
    }
    // This skin's bind space in the unified one: bind_unified(j) * bind_this(j)^-1, the same for
    // every joint when the two skins differ by one transform (identity for a shared skin).
    const Eigen::Matrix4d to_space =
        unified.bind[static_cast<std::size_t>(to_unified[0])] * binds.bind[0].inverse();
    for (std::size_t j = 1; j < binds.joint_nodes.size(); ++j) {
      const Eigen::Matrix4d here =
          unified.bind[static_cast<std::size_t>(to_unified[j])] * binds.bind[j].inverse();
      if ((here - to_space).norm() > kBindSpaceTolerance * (1 + to_space.norm())) {
        return Status::InvalidArgument(
            "the skin of node " + std::to_string(node_index) + " (skin " +
            std::to_string(node.skin) + ") binds joint node " +
            std::to_string(binds.joint_nodes[j]) +
            " in another pose than the skins before it: skinned nodes must share one bind pose");
      }
    }
    DEFORM_ASSIGN_OR_RETURN(
        FileMesh mesh,
        ReadSkinnedMesh(model, node.mesh, static_cast<int>(binds.joint_nodes.size()), limits));
    const int first = static_cast<int>(positions.size());
    if (positions.size() + static_cast<std::size_t>(mesh.positions.rows()) > limits.max_vertices) {
      return Status::ResourceExhausted("the glTF's skinned meshes hold more than " +
                                       std::to_string(limits.max_vertices) + " vertices");
    }
    if (triangles.size() + static_cast<std::size_t>(mesh.triangles.rows()) > limits.max_triangles) {
      return Status::ResourceExhausted("the glTF's skinned meshes hold more than " +
                                       std::to_string(limits.max_triangles) + " triangles");
    }
    for (Eigen::Index v = 0; v < mesh.positions.rows(); ++v) {
      const Eigen::Vector3d p = mesh.positions.row(v).transpose();
      positions.push_back(to_space.block<3, 3>(0, 0) * p + to_space.block<3, 1>(0, 3));
      std::vector<int> bones;
      std::vector<double> weights;
      const SkinWeights& w = mesh.joint_weights;
      for (int e = w.offsets[static_cast<std::size_t>(v)];
           e < w.offsets[static_cast<std::size_t>(v) + 1]; ++e) {
        bones.push_back(to_unified[static_cast<std::size_t>(w.bones[static_cast<std::size_t>(e)])]);
        weights.push_back(w.weights[static_cast<std::size_t>(e)]);
      }
      character.file.joint_weights.AddVertex(bones, weights);
    }
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      triangles.push_back(mesh.triangles.row(t).transpose() + Eigen::Vector3i::Constant(first));
    }
    character.nodes.push_back({node_index, first, static_cast<int>(mesh.positions.rows())});
  }
  character.file.joint_weights.num_bones = static_cast<int>(unified.joint_nodes.size());
  character.file.positions.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    character.file.positions.row(static_cast<Eigen::Index>(v)) = positions[v].transpose();
  }
  character.file.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    character.file.triangles.row(static_cast<Eigen::Index>(t)) = triangles[t].transpose();
  }
  character.joints = SkinJointsOf(model, unified, scene);
  character.joint_nodes = unified.joint_nodes;
  character.joint_bind = unified.bind;
  return character;
}

}  // namespace deform::gltf_internal
