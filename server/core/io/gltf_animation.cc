// Reading a glTF's animations with what sampling needs of the file: bytes -> tinygltf::Model
// (internal/gltf_load), the node hierarchy (internal/gltf_scene), the skins' joints and binds
// (internal/gltf_character), the channels (internal/gltf_animation_channels).
#include "core/io/gltf_animation.h"

#include <Eigen/LU>
#include <map>
#include <new>
#include <string>
#include <utility>

#include "internal/file_bytes.h"
#include "internal/gltf_animation_channels.h"
#include "internal/gltf_character.h"
#include "internal/gltf_load.h"
#include "internal/gltf_scene.h"

namespace deform {
namespace {

NodeTrs RestTrs(const tinygltf::Node& node) {
  NodeTrs trs;
  if (node.translation.size() == 3) {
    trs.translation =
        Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
  }
  if (node.rotation.size() == 4) {
    trs.rotation =
        Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2])
            .normalized();
  }
  if (node.scale.size() == 3)
    trs.scale = Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]);
  return trs;
}

StatusOr<GltfAnimations> ReadUnguarded(std::string_view bytes, const Skeleton& skeleton,
                                       const MeshLimits& limits) {
  tinygltf::Model model;
  DEFORM_RETURN_IF_ERROR(gltf_internal::LoadGltfModel(bytes, &model));
  DEFORM_ASSIGN_OR_RETURN(const gltf_internal::SceneNodes scene,
                          gltf_internal::ReadSceneNodes(model));
  DEFORM_ASSIGN_OR_RETURN(const gltf_internal::CharacterMesh character,
                          gltf_internal::ReadCharacterMesh(model, scene, limits));
  GltfAnimations result;
  DEFORM_ASSIGN_OR_RETURN(result.animations, gltf_internal::ReadAnimationChannels(model));
  result.node_parent = scene.parent;
  result.parents_first = scene.parents_first;
  for (std::size_t n = 0; n < model.nodes.size(); ++n) {
    const tinygltf::Node& node = model.nodes[n];
    result.rest_trs.push_back(RestTrs(node));
    result.has_matrix.push_back(!node.matrix.empty());
    // The local matrix as the scene reader builds it (ReadSceneNodes checked the numbers).
    Eigen::Matrix4d local = Eigen::Matrix4d::Identity();
    if (node.matrix.size() == 16) {
      for (int k = 0; k < 16; ++k) local(k % 4, k / 4) = node.matrix[static_cast<std::size_t>(k)];
    } else {
      local = result.rest_trs.back().Matrix();
    }
    result.rest_matrix.push_back(local);
  }
  std::map<std::string, std::size_t> joint_by_name;
  for (std::size_t j = 0; j < character.joints.size(); ++j) {
    joint_by_name.emplace(character.joints[j].name, j);
  }
  for (const Joint& joint : skeleton.joints()) result.joint_rest.push_back(joint.rest_position);
  result.bones = skeleton.bones();
  for (const Bone& bone : skeleton.bones()) {
    const std::string& name = skeleton.joint(bone.head_joint).name;
    const auto it = joint_by_name.find(name);
    if (it == joint_by_name.end()) {
      return Status::InvalidArgument("the skeleton's joint '" + name +
                                     "' is no joint of the glTF's skins (a skeleton read from "
                                     "another file?)");
    }
    const Eigen::FullPivLU<Eigen::Matrix4d> bind(character.joint_bind[it->second]);
    if (!bind.isInvertible()) {
      return Status::InvalidArgument("joint '" + name + "' has a singular bind matrix");
    }
    result.bone_head_node.push_back(character.joint_nodes[it->second]);
    result.bone_inverse_bind.push_back(bind.inverse());
  }
  return result;
}

}  // namespace

Eigen::Matrix4d NodeTrs::Matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = rotation.toRotationMatrix() * scale.asDiagonal();
  m.block<3, 1>(0, 3) = translation;
  return m;
}

StatusOr<GltfAnimations> ReadGltfAnimations(std::string_view bytes, const Skeleton& skeleton,
                                            const MeshLimits& limits) {
  try {
    return ReadUnguarded(bytes, skeleton, limits);
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted("out of memory while reading glTF animations");
  } catch (const std::exception& e) {
    return Status::InvalidArgument(std::string("glTF: ") + e.what());
  }
}

StatusOr<GltfAnimations> ReadGltfAnimationsFile(const std::string& path, const Skeleton& skeleton,
                                                const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(const std::string bytes, io_internal::ReadFileBytes(path, "glTF file"));
  StatusOr<GltfAnimations> animations = ReadGltfAnimations(bytes, skeleton, limits);
  if (!animations.ok()) return animations.status().WithContext(path);
  return animations;
}

StatusOr<int> FindAnimation(const GltfAnimations& animations, std::string_view name_or_index) {
  const int count = static_cast<int>(animations.animations.size());
  for (int a = 0; a < count; ++a) {
    if (animations.animations[static_cast<std::size_t>(a)].name == name_or_index) return a;
  }
  if (!name_or_index.empty() && name_or_index.size() < 10 &&
      name_or_index.find_first_not_of("0123456789") == std::string_view::npos) {
    const int index = std::stoi(std::string(name_or_index));
    if (index < count) return index;
  }
  std::string known;
  for (const GltfAnimation& animation : animations.animations) {
    known += (known.empty() ? "" : ", ") + ("'" + animation.name + "'");
  }
  return Status::NotFound("no animation '" + std::string(name_or_index) + "' in the glTF (" +
                          (count == 0 ? std::string("it has none")
                                      : "it has " + std::to_string(count) + ": " + known +
                                            "; or give an index from 0") +
                          ")");
}

}  // namespace deform
