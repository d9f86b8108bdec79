// Where a mesh, its skeleton and (optionally) its skinning weights come from: files, a skinned
// glTF rig, or the built-in knee phantom.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"

namespace deform {

struct ModelInput {
  TriangleMesh mesh;
  Skeleton skeleton;
  // Skinning weights over `skeleton`'s bones for every vertex of `mesh`, normalized
  // (NormalizeSkinWeights); from a weights file or a glTF rig, absent otherwise.
  std::optional<SkinWeights> weights;
  // For a glTF rig: per vertex in the file's own order, its vertex of `mesh` (see RigImport).
  // Empty when the mesh's vertices are the file's (OBJ, PLY, STL, OFF, the phantom).
  std::vector<int> file_vertex_to_mesh;
  std::string units;                  // "metre" for glTF; empty when the file does not say (OBJ...)
  std::string up_axis;                // "+Y" for glTF; empty when the file does not say
  std::string description;            // "phantom:2000" or the mesh path, for logs
  std::vector<std::string> warnings;  // a glTF rig's (RigImport::warnings); empty otherwise
  // Bone surfaces that came with the input: the phantom's femur, tibia and patella, a glTF rig's
  // (RigImport::bone_surfaces).
  std::vector<BoneSurface> bones;
};

// With an empty `mesh_path`, the knee phantom at `phantom_vertices` (the other paths must be empty
// too). A glTF rig (.gltf, .glb) gives mesh, skeleton and weights at once: a skeleton or weights
// path beside it is INVALID_ARGUMENT. Otherwise the mesh is read by its extension and the
// skeleton file is required (TGF, JSON); a weights file (.dmat, .csv), when given, is read and
// checked against both (LoadSkinWeightsFile).
StatusOr<ModelInput> LoadModelInput(const std::string& mesh_path, const std::string& skeleton_path,
                                    const std::string& weights_path, int phantom_vertices,
                                    const MeshLimits& limits = {});
// The same without a weights file.
StatusOr<ModelInput> LoadModelInput(const std::string& mesh_path, const std::string& skeleton_path,
                                    int phantom_vertices, const MeshLimits& limits = {});

}  // namespace deform
