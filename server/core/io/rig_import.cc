// The glTF rig import: bytes -> tinygltf::Model (internal/gltf_load), the node hierarchy
// (internal/gltf_scene), every skinned node's mesh and the union of their skins' joints
// (internal/gltf_character over internal/gltf_skin and internal/gltf_skinned_mesh), the skeleton
// (internal/gltf_rig_skeleton), weights mapped from joints to bones here, welding
// (internal/gltf_weld), and the bone surfaces among the unskinned mesh nodes
// (internal/gltf_bone_nodes).
#include "core/io/rig_import.h"

#include <filesystem>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "internal/file_bytes.h"
#include "internal/gltf_bone_nodes.h"
#include "internal/gltf_character.h"
#include "internal/gltf_load.h"
#include "internal/gltf_rig_skeleton.h"
#include "internal/gltf_scene.h"
#include "internal/gltf_skinned_mesh.h"
#include "internal/gltf_weld.h"
#include "internal/mesh_io_internal.h"

namespace deform {
namespace {

using gltf_internal::FileMesh;
using gltf_internal::RigSkeleton;
using gltf_internal::SkinJoint;

// Joints closer to their parent joint than this fraction of the mesh's bounding-box diagonal are
// merged into it.
constexpr double kJointMergeFraction = 1e-6;

// The most vertex-to-bone distances the weight mapping computes (a joint heading many bones costs
// one per bone per influence): beyond, the rig is refused rather than mapped for minutes.
constexpr long long kMaxNearestBoneWork = 200'000'000;

// Adds each file vertex's weighted position to the joints it is weighted to.
void AccumulateJointVertices(const FileMesh& file, std::vector<SkinJoint>* joints) {
  const SkinWeights& influences = file.joint_weights;
  for (int v = 0; v < influences.num_vertices(); ++v) {
    const Eigen::Vector3d position = file.positions.row(v).transpose();
    for (int e = influences.offsets[v]; e < influences.offsets[v + 1]; ++e) {
      SkinJoint& joint = (*joints)[static_cast<std::size_t>(influences.bones[e])];
      const double weight = influences.weights[e];
      joint.weight_total += weight;
      joint.weighted_position_sum += weight * position;
      joint.weighted_outer_sum += weight * position * position.transpose();
    }
  }
}

// The file vertices' joint influences as normalized weights on the rig's bones: a joint's weight
// goes to the bone starting at its skeleton joint, the nearest one where several start there.
StatusOr<SkinWeights> BoneWeights(const FileMesh& file, const RigSkeleton& rig) {
  const SkinWeights& influences = file.joint_weights;
  SkinWeights on_bones;
  on_bones.num_bones = rig.skeleton.num_bones();
  std::vector<int> bones;
  std::vector<double> weights;
  long long work = 0;
  for (int v = 0; v < influences.num_vertices(); ++v) {
    bones.clear();
    weights.clear();
    for (int e = influences.offsets[v]; e < influences.offsets[v + 1]; ++e) {
      const std::vector<int>& candidates =
          rig.bones_of_joint[static_cast<std::size_t>(influences.bones[e])];
      if (candidates.empty()) {  // cannot happen: a weighted joint always heads a bone
        return Status::Internal("glTF joint " + std::to_string(influences.bones[e]) +
                                " is weighted but heads no bone");
      }
      work += static_cast<long long>(candidates.size());
      if (work > kMaxNearestBoneWork) {
        return Status::ResourceExhausted(
            "the glTF's joints head too many bones each to map its weights to bones");
      }
      bones.push_back(candidates.size() == 1
                          ? candidates.front()
                          : gltf_internal::NearestBone(rig.skeleton, candidates,
                                                       file.positions.row(v).transpose()));
      weights.push_back(influences.weights[e]);
    }
    on_bones.AddVertex(bones, weights);
  }
  StatusOr<SkinWeights> normalized =
      NormalizeSkinWeights(on_bones, influences.num_vertices(), rig.skeleton.num_bones());
  if (!normalized.ok()) {
    return normalized.status().WithContext("the glTF's skinning weights (file vertex order)");
  }
  return normalized;
}

StatusOr<RigImport> ReadGltfUnguarded(std::string_view bytes, const MeshLimits& limits) {
  tinygltf::Model model;
  DEFORM_RETURN_IF_ERROR(gltf_internal::LoadGltfModel(bytes, &model));
  DEFORM_ASSIGN_OR_RETURN(const gltf_internal::SceneNodes scene,
                          gltf_internal::ReadSceneNodes(model));
  DEFORM_ASSIGN_OR_RETURN(gltf_internal::CharacterMesh character,
                          gltf_internal::ReadCharacterMesh(model, scene, limits));
  const FileMesh& file = character.file;
  std::vector<SkinJoint>& joints = character.joints;
  AccumulateJointVertices(file, &joints);
  DEFORM_ASSIGN_OR_RETURN(const RigSkeleton rig,
                          gltf_internal::BuildRigSkeleton(
                              joints, kJointMergeFraction * BoundingBoxDiagonal(file.positions)));
  DEFORM_ASSIGN_OR_RETURN(const SkinWeights file_weights, BoneWeights(file, rig));
  gltf_internal::WeldedMesh welded =
      gltf_internal::WeldSeams(file.positions, file_weights, file.triangles);
  DEFORM_RETURN_IF_ERROR(
      ValidateMesh(welded.mesh, limits).WithContext("the glTF's skinned mesh (welded)"));
  std::vector<std::string> result_warnings;
  std::vector<gltf_internal::BoneNodeMesh> bone_nodes = gltf_internal::ReadBoneNodeMeshes(
      model, scene, character, limits, BoneSurfaceLimits{}, &result_warnings);
  RigImport result;
  result.bone_surfaces = gltf_internal::SelectBoneSurfaces(std::move(bone_nodes), joints, rig,
                                                           welded.mesh, &result_warnings);
  result.mesh = std::move(welded.mesh);
  result.skeleton = rig.skeleton;
  result.weights = std::move(welded.weights);
  result.file_vertex_to_mesh = std::move(welded.file_vertex_to_mesh);
  result.unused_file_vertices = std::move(welded.unused_vertices);
  const double diagonal = BoundingBoxDiagonal(result.mesh.vertices);
  if (diagonal < kPlausibleDiagonalMetres[0] || diagonal > kPlausibleDiagonalMetres[1]) {
    result.warnings.push_back(
        "the skinned mesh's bounding-box diagonal is " + std::to_string(diagonal) +
        " units, read as metres (glTF's unit): implausible for a limb or a character (" +
        std::to_string(kPlausibleDiagonalMetres[0]) + " to " +
        std::to_string(kPlausibleDiagonalMetres[1]) +
        " m); the file may be in another unit (centimetres?)");
  }
  if (character.nodes.size() > 1) {
    std::string line = "the file's vertices come from " + std::to_string(character.nodes.size()) +
                       " skinned mesh nodes, in node order:";
    for (const gltf_internal::SkinnedNodeVertices& range : character.nodes) {
      const std::string& name = model.nodes[static_cast<std::size_t>(range.node)].name;
      line += " " + std::to_string(range.first_vertex) + ".." +
              std::to_string(range.first_vertex + range.num_vertices - 1) + " node " +
              std::to_string(range.node) + (name.empty() ? "" : " '" + name + "'") + ";";
    }
    line.pop_back();
    result.warnings.push_back(line);
  }
  result.warnings.insert(result.warnings.end(), result_warnings.begin(), result_warnings.end());
  for (const gltf_internal::SkinnedNodeVertices& range : character.nodes) {
    const std::string& name = model.nodes[static_cast<std::size_t>(range.node)].name;
    result.skinned_nodes.push_back({range.node,
                                    name.empty() ? "node" + std::to_string(range.node) : name,
                                    range.first_vertex, range.num_vertices});
  }
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
