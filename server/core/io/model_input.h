// Where a mesh and its skeleton come from: files, or the built-in knee phantom.
#pragma once

#include <string>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"

namespace deform {

struct ModelInput {
  TriangleMesh mesh;
  Skeleton skeleton;
  std::string description;  // "phantom:2000" or the mesh path, for logs
};

// With an empty `mesh_path`, the knee phantom at `phantom_vertices` (and `skeleton_path` must be
// empty too). Otherwise both files are read: the mesh by its extension, the skeleton as TGF
// (.tgf) or JSON. INVALID_ARGUMENT when only one of the two paths is given.
StatusOr<ModelInput> LoadModelInput(const std::string& mesh_path, const std::string& skeleton_path,
                                    int phantom_vertices, const MeshLimits& limits = {});

}  // namespace deform
