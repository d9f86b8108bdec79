// Where a command-line client's mesh comes from: the built-in phantom, uploaded files, or a mesh
// the server already holds.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lib/deform_client.h"

namespace deform::cli {

struct MeshSource {
  std::string mesh_id;    // non-empty: use this loaded mesh (nothing is loaded)
  std::string mesh_path;  // non-empty: upload this file with `skeleton_path` (none for a glTF rig)
  std::string skeleton_path;
  std::string weights_path;  // optional with `mesh_path`: the rig's skinning weights (.dmat, .csv)
  // With `mesh_path`: bone surfaces "FILE:BONE" (client::AddBoneSurfaceFile).
  std::vector<std::string> bone_surfaces;
  bool phantom_without_bones = false;  // the phantom without its femur, tibia and patella
  int phantom_vertices = 0;  // otherwise: load the phantom at this resolution (0 = default)
  // When loading: how the server blends bone rotations near a joint.
  deform::v1::RotationBlend rotation_blend = deform::v1::ROTATION_BLEND_UNSPECIFIED;
  // When loading: MethodOptions.constraints (unset: the server's defaults, both on).
  std::optional<bool> contacts;
  std::optional<bool> keep_volume;

  // "phantom", the mesh file, or the mesh id: for reports.
  std::string Description() const;
};

// Loads or looks up the mesh and fills `summary`. `loaded` tells whether this call loaded it (and
// so owns it). Returns the server's (or the file reader's) status.
grpc::Status AcquireMesh(client::DeformClient& client, const MeshSource& source,
                         deform::v1::MeshSummary* summary, bool* loaded);

}  // namespace deform::cli
