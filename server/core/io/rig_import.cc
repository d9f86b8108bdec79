// The glTF rig import: bytes -> tinygltf::Model (internal/gltf_load), the skinned node and its
// skin, joints and their hierarchy (internal/gltf_scene), primitives through checked accessors
// (internal/gltf_accessors), the skeleton (internal/gltf_rig_skeleton), weights mapped to bones,
// and welding (internal/gltf_weld).
#include "core/io/rig_import.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <new>
#include <set>
#include <string>
#include <utility>

#include "internal/file_bytes.h"
#include "internal/gltf_accessors.h"
#include "internal/gltf_load.h"
#include "internal/gltf_rig_skeleton.h"
#include "internal/gltf_scene.h"
#include "internal/gltf_weld.h"
#include "internal/mesh_io_internal.h"

namespace deform {
namespace {

using gltf_internal::AccessorSpec;
using gltf_internal::AccessorValues;
using gltf_internal::ReadAccessor;
using Normalization = AccessorSpec::IntegerNormalization;

// Joints closer to their parent joint than this fraction of the mesh's bounding-box diagonal are
// merged into it.
constexpr double kJointMergeFraction = 1e-6;

// The skinned mesh, concatenated over its primitives, in file order.
struct FileMesh {
  Positions positions;
  Triangles triangles;
  // Per file vertex, its (skin joint, weight) influences with weight > 0.
  std::vector<std::vector<std::pair<int, double>>> influences;
};

StatusOr<int> FindSkinnedNode(const tinygltf::Model& model) {
  std::vector<int> skinned;
  for (std::size_t n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes[n].mesh >= 0 && model.nodes[n].skin >= 0)
      skinned.push_back(static_cast<int>(n));
  }
  if (skinned.empty()) {
    return Status::InvalidArgument(
        "no skin: the glTF has no node with both a mesh and a skin (export the mesh with its "
        "armature / skin, and its skinning weights)");
  }
  if (skinned.size() > 1) {
    return Status::InvalidArgument("the glTF has " + std::to_string(skinned.size()) +
                                   " skinned mesh nodes (nodes " + std::to_string(skinned[0]) +
                                   " and " + std::to_string(skinned[1]) +
                                   "...); deformd deforms one: export the limb's mesh alone");
  }
  const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(skinned[0])];
  if (static_cast<std::size_t>(node.mesh) >= model.meshes.size()) {
    return Status::InvalidArgument("node " + std::to_string(skinned[0]) + " refers to mesh " +
                                   std::to_string(node.mesh) + ", which does not exist");
  }
  if (static_cast<std::size_t>(node.skin) >= model.skins.size()) {
    return Status::InvalidArgument("node " + std::to_string(skinned[0]) + " refers to skin " +
                                   std::to_string(node.skin) + ", which does not exist");
  }
  return skinned[0];
}

// Appends one triangle primitive's vertices, triangles and influences to `mesh`.
Status AppendPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                       const std::string& where, int num_joints, const MeshLimits& limits,
                       FileMesh* mesh) {
  if (primitive.mode != TINYGLTF_MODE_TRIANGLES) {
    return Status::InvalidArgument(where + " has mode " + std::to_string(primitive.mode) +
                                   "; a skinned mesh must be triangles (mode 4)");
  }
  const auto attribute = [&primitive](const std::string& name) {
    const auto it = primitive.attributes.find(name);
    return it == primitive.attributes.end() ? -1 : it->second;
  };
  if (attribute("POSITION") < 0) return Status::InvalidArgument(where + " has no POSITION");
  const std::size_t first = static_cast<std::size_t>(mesh->positions.rows());
  const std::uint64_t vertex_room =
      limits.max_vertices - std::min<std::uint64_t>(first, limits.max_vertices);
  DEFORM_ASSIGN_OR_RETURN(const AccessorValues positions,
                          ReadAccessor(model, attribute("POSITION"),
                                       {"POSITION of " + where,
                                        {TINYGLTF_TYPE_VEC3},
                                        {TINYGLTF_COMPONENT_TYPE_FLOAT},
                                        Normalization::kNever,
                                        vertex_room,
                                        "vertices (with the primitives before it)"}));
  const int count = positions.count;
  // Influences: JOINTS_n / WEIGHTS_n pairs.
  std::vector<std::vector<std::pair<int, double>>> influences(static_cast<std::size_t>(count));
  if (attribute("JOINTS_0") < 0 || attribute("WEIGHTS_0") < 0) {
    return Status::InvalidArgument(where +
                                   " has no JOINTS_0 and WEIGHTS_0; every primitive of a "
                                   "skinned mesh needs them");
  }
  for (int set = 0;; ++set) {
    const std::string joints_name = "JOINTS_" + std::to_string(set);
    const std::string weights_name = "WEIGHTS_" + std::to_string(set);
    const int joints_index = attribute(joints_name);
    const int weights_index = attribute(weights_name);
    if (joints_index < 0 && weights_index < 0) break;
    if (joints_index < 0 || weights_index < 0) {
      return Status::InvalidArgument(where + " has " +
                                     (joints_index < 0 ? weights_name : joints_name) + " without " +
                                     (joints_index < 0 ? joints_name : weights_name));
    }
    DEFORM_ASSIGN_OR_RETURN(const AccessorValues joints,
                            ReadAccessor(model, joints_index,
                                         {joints_name + " of " + where,
                                          {TINYGLTF_TYPE_VEC4},
                                          {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                          Normalization::kNever,
                                          static_cast<std::uint64_t>(count),
                                          "vertices"}));
    DEFORM_ASSIGN_OR_RETURN(
        const AccessorValues weights,
        ReadAccessor(model, weights_index,
                     {weights_name + " of " + where,
                      {TINYGLTF_TYPE_VEC4},
                      {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                      Normalization::kRequired,
                      static_cast<std::uint64_t>(count),
                      "vertices"}));
    if (joints.count != count || weights.count != count) {
      return Status::InvalidArgument(where + ": " + joints_name + " and " + weights_name +
                                     " must have one element per vertex (" + std::to_string(count) +
                                     ")");
    }
    for (int v = 0; v < count; ++v) {
      for (int c = 0; c < 4; ++c) {
        const double joint = joints.at(v, c);
        const double weight = weights.at(v, c);
        if (joint >= num_joints) {
          return Status::InvalidArgument(
              where + ": " + joints_name + " of vertex " + std::to_string(v) + " names joint " +
              std::to_string(static_cast<long long>(joint)) + " but the skin has " +
              std::to_string(num_joints) + " joints");
        }
        if (weight < 0) {
          return Status::InvalidArgument(where + ": " + weights_name + " of vertex " +
                                         std::to_string(v) + " is negative");
        }
        if (weight > 0)
          influences[static_cast<std::size_t>(v)].emplace_back(static_cast<int>(joint), weight);
      }
    }
  }
  // Triangles: indexed, or consecutive vertex triples.
  std::vector<int> corners;
  if (primitive.indices >= 0) {
    DEFORM_ASSIGN_OR_RETURN(const AccessorValues indices,
                            ReadAccessor(model, primitive.indices,
                                         {"indices of " + where,
                                          {TINYGLTF_TYPE_SCALAR},
                                          {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                          Normalization::kNever,
                                          3 * static_cast<std::uint64_t>(limits.max_triangles),
                                          "indices (3 per triangle)"}));
    corners.reserve(indices.values.size());
    for (std::size_t k = 0; k < indices.values.size(); ++k) {
      if (indices.values[k] >= count) {
        return Status::InvalidArgument(where + ": index " + std::to_string(k) + " is " +
                                       std::to_string(static_cast<long long>(indices.values[k])) +
                                       " but the primitive has " + std::to_string(count) +
                                       " vertices");
      }
      corners.push_back(static_cast<int>(indices.values[k]));
    }
  } else {
    corners.resize(static_cast<std::size_t>(count));
    for (int v = 0; v < count; ++v) corners[static_cast<std::size_t>(v)] = v;
  }
  if (corners.empty() || corners.size() % 3 != 0) {
    return Status::InvalidArgument(where + " has " + std::to_string(corners.size()) +
                                   " triangle corners, not a positive multiple of 3");
  }
  const std::size_t first_triangle = static_cast<std::size_t>(mesh->triangles.rows());
  if (first_triangle + corners.size() / 3 > limits.max_triangles) {
    return mesh_io_internal::TooManyTriangles("the glTF's skinned mesh", limits.max_triangles);
  }
  mesh->positions.conservativeResize(
      static_cast<Eigen::Index>(first + static_cast<std::size_t>(count)), 3);
  for (int v = 0; v < count; ++v) {
    for (int c = 0; c < 3; ++c)
      mesh->positions(static_cast<Eigen::Index>(first) + v, c) = positions.at(v, c);
  }
  mesh->triangles.conservativeResize(static_cast<Eigen::Index>(first_triangle + corners.size() / 3),
                                     3);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    mesh->triangles(static_cast<Eigen::Index>(first_triangle + k / 3),
                    static_cast<Eigen::Index>(k % 3)) = static_cast<int>(first) + corners[k];
  }
  for (auto& vertex : influences) mesh->influences.push_back(std::move(vertex));
  return Status::Ok();
}

StatusOr<FileMesh> ReadSkinnedMesh(const tinygltf::Model& model, int mesh_index, int num_joints,
                                   const MeshLimits& limits) {
  const tinygltf::Mesh& gltf_mesh = model.meshes[static_cast<std::size_t>(mesh_index)];
  if (gltf_mesh.primitives.empty()) {
    return Status::InvalidArgument("mesh " + std::to_string(mesh_index) + " has no primitives");
  }
  FileMesh mesh;
  mesh.positions.resize(0, 3);
  mesh.triangles.resize(0, 3);
  for (std::size_t p = 0; p < gltf_mesh.primitives.size(); ++p) {
    DEFORM_RETURN_IF_ERROR(
        AppendPrimitive(model, gltf_mesh.primitives[p],
                        "primitive " + std::to_string(p) + " of mesh " + std::to_string(mesh_index),
                        num_joints, limits, &mesh));
  }
  return mesh;
}

// The skin's joints as positions in bind space, named and linked to their nearest joint ancestor.
StatusOr<std::vector<gltf_internal::SkinJoint>> ReadSkinJoints(
    const tinygltf::Model& model, const tinygltf::Skin& skin, int skin_index,
    const gltf_internal::SceneNodes& scene) {
  const std::string where = "skin " + std::to_string(skin_index);
  if (skin.joints.empty()) return Status::InvalidArgument(where + " has no joints");
  std::map<int, int> joint_of_node;
  for (std::size_t j = 0; j < skin.joints.size(); ++j) {
    const int node = skin.joints[j];
    if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size()) {
      return Status::InvalidArgument(where + "'s joint " + std::to_string(j) + " is node " +
                                     std::to_string(node) + ", which does not exist");
    }
    if (!joint_of_node.emplace(node, static_cast<int>(j)).second) {
      return Status::InvalidArgument(where + " lists node " + std::to_string(node) + " twice");
    }
  }
  std::vector<gltf_internal::SkinJoint> joints(skin.joints.size());
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
    for (std::size_t j = 0; j < joints.size(); ++j) {
      Eigen::Matrix4d inverse_bind;
      for (int k = 0; k < 16; ++k) inverse_bind(k % 4, k / 4) = matrices.at(static_cast<int>(j), k);
      const Eigen::Matrix4d bind = inverse_bind.inverse();
      if (!bind.allFinite() || std::abs(inverse_bind.determinant()) < 1e-12) {
        return Status::InvalidArgument(where + "'s inverse bind matrix " + std::to_string(j) +
                                       " is not invertible");
      }
      joints[j].position = bind.block<3, 1>(0, 3);
    }
  } else {
    for (std::size_t j = 0; j < joints.size(); ++j) {
      joints[j].position = scene.world[static_cast<std::size_t>(skin.joints[j])].block<3, 1>(0, 3);
    }
  }
  std::set<std::string> names;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const int node = skin.joints[j];
    std::string name = model.nodes[static_cast<std::size_t>(node)].name;
    if (name.empty()) name = "node" + std::to_string(node);
    std::string unique = name;
    for (int k = 2; names.count(unique) != 0; ++k) unique = name + "_" + std::to_string(k);
    names.insert(unique);
    joints[j].name = unique;
    for (int at = scene.parent[static_cast<std::size_t>(node)]; at >= 0;
         at = scene.parent[static_cast<std::size_t>(at)]) {
      const auto it = joint_of_node.find(at);
      if (it != joint_of_node.end()) {
        joints[j].parent = it->second;
        break;
      }
    }
  }
  return joints;
}

StatusOr<RigImport> ReadGltfUnguarded(std::string_view bytes, const MeshLimits& limits) {
  tinygltf::Model model;
  DEFORM_RETURN_IF_ERROR(gltf_internal::LoadGltfModel(bytes, &model));
  DEFORM_ASSIGN_OR_RETURN(const int node_index, FindSkinnedNode(model));
  DEFORM_ASSIGN_OR_RETURN(const gltf_internal::SceneNodes scene,
                          gltf_internal::ReadSceneNodes(model));
  const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(node_index)];
  const tinygltf::Skin& skin = model.skins[static_cast<std::size_t>(node.skin)];
  DEFORM_ASSIGN_OR_RETURN(std::vector<gltf_internal::SkinJoint> joints,
                          ReadSkinJoints(model, skin, node.skin, scene));
  DEFORM_ASSIGN_OR_RETURN(
      FileMesh file, ReadSkinnedMesh(model, node.mesh, static_cast<int>(joints.size()), limits));
  const int num_file = static_cast<int>(file.positions.rows());
  for (int v = 0; v < num_file; ++v) {
    for (const auto& [joint, weight] : file.influences[static_cast<std::size_t>(v)]) {
      joints[static_cast<std::size_t>(joint)].weight_total += weight;
      const Eigen::Vector3d position = file.positions.row(v).transpose();
      joints[static_cast<std::size_t>(joint)].weighted_position_sum += weight * position;
      joints[static_cast<std::size_t>(joint)].weighted_outer_sum +=
          weight * position * position.transpose();
    }
  }
  const double diagonal = BoundingBoxDiagonal(file.positions);
  DEFORM_ASSIGN_OR_RETURN(const gltf_internal::RigSkeleton rig,
                          gltf_internal::BuildRigSkeleton(joints, kJointMergeFraction * diagonal));

  // Weights on bones, per file vertex, then normalised.
  SkinWeights file_weights;
  file_weights.num_bones = rig.skeleton.num_bones();
  std::vector<int> bones;
  std::vector<double> weights;
  for (int v = 0; v < num_file; ++v) {
    bones.clear();
    weights.clear();
    for (const auto& [joint, weight] : file.influences[static_cast<std::size_t>(v)]) {
      const std::vector<int>& candidates = rig.bones_of_joint[static_cast<std::size_t>(joint)];
      bones.push_back(candidates.size() == 1
                          ? candidates.front()
                          : gltf_internal::NearestBone(rig.skeleton, candidates,
                                                       file.positions.row(v).transpose()));
      weights.push_back(weight);
    }
    file_weights.AddVertex(bones, weights);
  }
  StatusOr<SkinWeights> normalized =
      NormalizeSkinWeights(file_weights, num_file, rig.skeleton.num_bones());
  if (!normalized.ok()) {
    return normalized.status().WithContext("the glTF's skinning weights (file vertex order)");
  }

  gltf_internal::WeldedMesh welded =
      gltf_internal::WeldSeams(file.positions, *normalized, file.triangles);
  DEFORM_RETURN_IF_ERROR(
      ValidateMesh(welded.mesh, limits).WithContext("the glTF's skinned mesh (welded)"));
  RigImport result{std::move(welded.mesh), rig.skeleton, std::move(welded.weights),
                   std::move(welded.file_vertex_to_mesh)};
  return result;
}

}  // namespace

StatusOr<RigImport> ReadGltf(std::string_view bytes, const MeshLimits& limits) {
  try {
    return ReadGltfUnguarded(bytes, limits);
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted("out of memory while reading glTF data");
  } catch (const std::exception& e) {
    return Status::InvalidArgument(std::string("glTF: ") + e.what());
  }
}

StatusOr<RigImport> ReadGltfFile(const std::string& path, const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const std::string bytes, io_internal::ReadFileBytes(path, "glTF file"));
  StatusOr<RigImport> rig = ReadGltf(bytes, limits);
  if (!rig.ok()) return rig.status().WithContext(path);
  return rig;
}

bool IsGltfPath(std::string_view path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  return mesh_io_internal::EqualsIgnoreCase(extension, ".gltf") ||
         mesh_io_internal::EqualsIgnoreCase(extension, ".glb");
}

}  // namespace deform
