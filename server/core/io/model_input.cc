#include "core/io/model_input.h"

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/rig_import.h"
#include "core/io/skeleton_io.h"
#include "core/io/skin_weights_io.h"

namespace deform {
namespace {

StatusOr<ModelInput> LoadPhantom(int phantom_vertices, const MeshLimits& limits) {
  if (static_cast<std::size_t>(phantom_vertices) > limits.max_vertices) {
    return Status::ResourceExhausted("phantom of " + std::to_string(phantom_vertices) +
                                     " vertices exceeds the limit of " +
                                     std::to_string(limits.max_vertices));
  }
  DEFORM_ASSIGN_OR_RETURN(KneePhantom phantom, MakeKneePhantom(phantom_vertices));
  ModelInput input;
  input.mesh = std::move(phantom.mesh);
  input.skeleton = std::move(phantom.skeleton);
  input.bones = std::move(phantom.bones);
  input.description = "phantom:" + std::to_string(phantom_vertices);
  return input;
}

StatusOr<ModelInput> LoadGltfRig(const std::string& path, const MeshLimits& limits) {
  DEFORM_ASSIGN_OR_RETURN(RigImport rig, ReadGltfFile(path, limits));
  ModelInput input;
  input.mesh = std::move(rig.mesh);
  input.skeleton = std::move(rig.skeleton);
  input.weights = std::move(rig.weights);
  input.file_vertex_to_mesh = std::move(rig.file_vertex_to_mesh);
  input.units = std::move(rig.units);
  input.up_axis = std::move(rig.up_axis);
  input.warnings = std::move(rig.warnings);
  input.bones = std::move(rig.bone_surfaces);
  input.description = path;
  return input;
}

}  // namespace

StatusOr<ModelInput> LoadModelInput(const std::string& mesh_path, const std::string& skeleton_path,
                                    const std::string& weights_path, int phantom_vertices,
                                    const MeshLimits& limits) {
  if (mesh_path.empty()) {
    if (!skeleton_path.empty()) {
      return Status::InvalidArgument("a skeleton was given without a mesh");
    }
    if (!weights_path.empty()) {
      return Status::InvalidArgument("skinning weights were given without a mesh");
    }
    return LoadPhantom(phantom_vertices, limits);
  }
  if (IsGltfPath(mesh_path)) {
    if (!skeleton_path.empty()) {
      return Status::InvalidArgument("mesh '" + mesh_path +
                                     "' is a glTF rig with its own skeleton: give no skeleton "
                                     "file beside it (got '" +
                                     skeleton_path + "')");
    }
    if (!weights_path.empty()) {
      return Status::InvalidArgument("mesh '" + mesh_path +
                                     "' is a glTF rig with its own skinning weights: give no "
                                     "weights file beside it (got '" +
                                     weights_path + "')");
    }
    return LoadGltfRig(mesh_path, limits);
  }
  if (skeleton_path.empty()) {
    return Status::InvalidArgument("mesh '" + mesh_path + "' needs a skeleton file too");
  }
  ModelInput input;
  DEFORM_ASSIGN_OR_RETURN(input.mesh, ReadMeshFile(mesh_path, limits));
  DEFORM_ASSIGN_OR_RETURN(input.skeleton, ReadSkeletonFile(skeleton_path));
  if (!weights_path.empty()) {
    DEFORM_ASSIGN_OR_RETURN(input.weights,
                            LoadSkinWeightsFile(weights_path, input.mesh.num_vertices(),
                                                input.skeleton.num_bones(), limits));
  }
  input.description = mesh_path;
  return input;
}

StatusOr<ModelInput> LoadModelInput(const std::string& mesh_path, const std::string& skeleton_path,
                                    int phantom_vertices, const MeshLimits& limits) {
  return LoadModelInput(mesh_path, skeleton_path, std::string(), phantom_vertices, limits);
}

}  // namespace deform
