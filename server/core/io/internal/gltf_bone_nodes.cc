#include "gltf_bone_nodes.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry/enclosed_volume.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/triangle_bvh.h"
#include "core/geometry/volume_closure.h"
#include "gltf_skinned_mesh.h"
#include "gltf_weld.h"

namespace deform::gltf_internal {
namespace {

std::string NodeName(const tinygltf::Model& model, int node) {
  const std::string& name = model.nodes[static_cast<std::size_t>(node)].name;
  return name.empty() ? "node" + std::to_string(node) : name;
}

std::string Describe(const tinygltf::Model& model, int node) {
  return "mesh node " + std::to_string(node) + " '" + NodeName(model, node) + "'";
}

// The skin joint carrying `node`: the node itself when it is a joint, else its nearest joint
// ancestor; -1 for none.
int CarryingJoint(int node, const SceneNodes& scene, const std::map<int, int>& joint_of_node) {
  for (int n = node; n >= 0; n = scene.parent[static_cast<std::size_t>(n)]) {
    const auto it = joint_of_node.find(n);
    if (it != joint_of_node.end()) return it->second;
  }
  return -1;
}

// `file` welded by exact position (glTF splits vertices at UV and normal seams).
TriangleMesh WeldByPosition(const FileMesh& file) {
  SkinWeights one_bone;
  one_bone.num_bones = 1;
  for (Eigen::Index v = 0; v < file.positions.rows(); ++v) one_bone.AddVertex({0}, {1.0});
  return WeldSeams(file.positions, one_bone, file.triangles).mesh;
}

}  // namespace

std::vector<BoneNodeMesh> ReadBoneNodeMeshes(const tinygltf::Model& model, const SceneNodes& scene,
                                             const CharacterMesh& character,
                                             const MeshLimits& limits,
                                             const BoneSurfaceLimits& bone_limits,
                                             std::vector<std::string>* warnings) {
  std::map<int, int> joint_of_node;
  for (std::size_t j = 0; j < character.joint_nodes.size(); ++j) {
    joint_of_node.emplace(character.joint_nodes[j], static_cast<int>(j));
  }
  std::vector<BoneNodeMesh> meshes;
  std::size_t triangles_left = bone_limits.max_total_triangles;
  for (int node = 0; node < static_cast<int>(model.nodes.size()); ++node) {
    const tinygltf::Node& gltf_node = model.nodes[static_cast<std::size_t>(node)];
    if (gltf_node.mesh < 0 || gltf_node.skin >= 0) continue;
    const int joint = CarryingJoint(node, scene, joint_of_node);
    if (joint < 0) continue;  // scenery, not part of the character's skeleton
    const std::string what = Describe(model, node);
    const auto skip = [&](const std::string& reason) {
      warnings->push_back(what + " under joint '" +
                          character.joints[static_cast<std::size_t>(joint)].name +
                          "' is not a bone surface: " + reason);
    };
    if (gltf_node.mesh >= static_cast<int>(model.meshes.size())) {
      skip("its mesh " + std::to_string(gltf_node.mesh) + " does not exist");
      continue;
    }
    if (static_cast<int>(meshes.size()) >= bone_limits.max_surfaces) {
      skip("more than " + std::to_string(bone_limits.max_surfaces) + " bone surfaces");
      continue;
    }
    MeshLimits room = limits;
    room.max_triangles = std::min(limits.max_triangles, triangles_left);
    StatusOr<FileMesh> file = ReadStaticMesh(model, gltf_node.mesh, room);
    if (!file.ok()) {
      skip(file.status().message());
      continue;
    }
    const int joint_node = character.joint_nodes[static_cast<std::size_t>(joint)];
    const Eigen::FullPivLU<Eigen::Matrix4d> joint_world(
        scene.world[static_cast<std::size_t>(joint_node)]);
    if (!joint_world.isInvertible()) {
      skip("its joint's world transform is singular");
      continue;
    }
    const Eigen::Matrix4d to_bind = character.joint_bind[static_cast<std::size_t>(joint)] *
                                    joint_world.inverse() *
                                    scene.world[static_cast<std::size_t>(node)];
    if (!to_bind.allFinite()) {
      skip("its transform into the bind pose is not finite");
      continue;
    }
    for (Eigen::Index v = 0; v < file->positions.rows(); ++v) {
      const Eigen::Vector3d p = file->positions.row(v).transpose();
      file->positions.row(v) =
          (to_bind.block<3, 3>(0, 0) * p + to_bind.block<3, 1>(0, 3)).transpose();
    }
    BoneNodeMesh mesh{node, NodeName(model, node), joint, WeldByPosition(*file)};
    triangles_left -= static_cast<std::size_t>(mesh.mesh.num_triangles());
    meshes.push_back(std::move(mesh));
  }
  return meshes;
}

namespace {

// Why `mesh` cannot be a bone surface on its own (empty when it can), orienting it outward.
std::string ShapeProblem(TriangleMesh* mesh) {
  const Status valid = ValidateMesh(*mesh);
  if (!valid.ok()) return valid.message();
  if (!IsClosed(mesh->triangles)) return "it is not closed (an edge not shared by two triangles)";
  const double volume = EnclosedVolume(mesh->vertices, mesh->triangles);
  const double diagonal = BoundingBoxDiagonal(mesh->vertices);
  if (!(std::abs(volume) > 1e-9 * diagonal * diagonal * diagonal)) return "it encloses no volume";
  if (volume < 0) mesh->triangles.col(1).swap(mesh->triangles.col(2));
  return "";
}

// The bone carrying joint j's surfaces: of the bones starting at its skeleton joint, the nearest
// to `centroid`; a joint heading none passes to its parent. -1 when no ancestor heads a bone.
int CarryingBone(int j, const std::vector<SkinJoint>& joints, const RigSkeleton& rig,
                 const Eigen::Vector3d& centroid) {
  for (int k = j; k >= 0; k = joints[static_cast<std::size_t>(k)].parent) {
    const std::vector<int>& bones = rig.bones_of_joint[static_cast<std::size_t>(k)];
    if (!bones.empty()) {
      return bones.size() == 1 ? bones.front() : NearestBone(rig.skeleton, bones, centroid);
    }
  }
  return -1;
}

}  // namespace

std::vector<BoneSurface> SelectBoneSurfaces(std::vector<BoneNodeMesh> candidates,
                                            const std::vector<SkinJoint>& joints,
                                            const RigSkeleton& rig, const TriangleMesh& skin,
                                            std::vector<std::string>* warnings) {
  std::vector<BoneSurface> surfaces;
  if (candidates.empty()) return surfaces;
  const TriangleBvh inside_skin(
      VolumeClosure(skin.triangles, skin.num_vertices()).ClosedMesh(skin.vertices));
  for (BoneNodeMesh& candidate : candidates) {
    const auto skip = [&](const std::string& reason) {
      warnings->push_back("mesh node " + std::to_string(candidate.node) + " '" + candidate.name +
                          "' under joint '" +
                          joints[static_cast<std::size_t>(candidate.joint)].name +
                          "' is not a bone surface: " + reason);
    };
    const std::string problem = ShapeProblem(&candidate.mesh);
    if (!problem.empty()) {
      skip(problem);
      continue;
    }
    const Positions& vertices = candidate.mesh.vertices;
    int outside = 0;
    for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
      if (!inside_skin.Contains(vertices.row(v).transpose())) ++outside;
    }
    if (outside > 0) {
      skip(std::to_string(outside) + " of its " + std::to_string(vertices.rows()) +
           " vertices are outside the skin (a prop, not a bone)");
      continue;
    }
    const TriangleBvh bone(candidate.mesh);
    int entered = 0;
    for (Eigen::Index v = 0; v < skin.vertices.rows(); ++v) {
      const Eigen::Vector3d x = skin.vertices.row(v).transpose();
      if ((x.array() >= bone.lower().array()).all() && (x.array() <= bone.upper().array()).all() &&
          bone.Contains(x)) {
        ++entered;
      }
    }
    if (entered > 0) {
      skip(std::to_string(entered) + " skin vertices are inside it at rest");
      continue;
    }
    const Eigen::Vector3d centroid = vertices.colwise().mean().transpose();
    const int carrier = CarryingBone(candidate.joint, joints, rig, centroid);
    if (carrier < 0) {
      skip("no bone starts at its joint or an ancestor of it");
      continue;
    }
    BoneSurface surface;
    surface.name = std::move(candidate.name);
    surface.bone = carrier;
    surface.mesh = std::move(candidate.mesh);
    surfaces.push_back(std::move(surface));
  }
  return surfaces;
}

}  // namespace deform::gltf_internal
