#include "core/io/model_input.h"

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"

namespace deform {

StatusOr<ModelInput> LoadModelInput(const std::string& mesh_path, const std::string& skeleton_path,
                                    int phantom_vertices, const MeshLimits& limits) {
  ModelInput input;
  if (mesh_path.empty()) {
    if (!skeleton_path.empty()) {
      return Status::InvalidArgument("a skeleton was given without a mesh");
    }
    if (static_cast<std::size_t>(phantom_vertices) > limits.max_vertices) {
      return Status::ResourceExhausted("phantom of " + std::to_string(phantom_vertices) +
                                       " vertices exceeds the limit of " +
                                       std::to_string(limits.max_vertices));
    }
    DEFORM_ASSIGN_OR_RETURN(KneePhantom phantom, MakeKneePhantom(phantom_vertices));
    input.mesh = std::move(phantom.mesh);
    input.skeleton = std::move(phantom.skeleton);
    input.description = "phantom:" + std::to_string(phantom_vertices);
    return input;
  }
  if (skeleton_path.empty()) {
    return Status::InvalidArgument("mesh '" + mesh_path + "' needs a skeleton file too");
  }
  DEFORM_ASSIGN_OR_RETURN(input.mesh, ReadMeshFile(mesh_path, limits));
  DEFORM_ASSIGN_OR_RETURN(input.skeleton, ReadSkeletonFile(skeleton_path));
  input.description = mesh_path;
  return input;
}

}  // namespace deform
