// The order of a frame's vertices against the local model's. deformd returns frames in the file's
// vertex order (its MeshFileMetadata): for OBJ, PLY, STL, OFF and the phantom that is the solved
// mesh's order itself (the server and LoadModelInput read the bytes with the same readers); for a
// glTF rig, the file's unwelded vertices, each mapped to its welded vertex by
// ModelInput::file_vertex_to_mesh (the same ReadGltf on the same bytes on both sides).
#pragma once

#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"

namespace deform::animation {

class VertexOrder {
 public:
  // `file_vertex_to_mesh` as ModelInput gives it (empty: the same order); `mesh_vertices` the
  // solved mesh's vertex count. INVALID_ARGUMENT when a solved vertex has no file vertex or the
  // map points outside the mesh.
  static StatusOr<VertexOrder> Create(const std::vector<int>& file_vertex_to_mesh,
                                      int mesh_vertices);

  // Vertices of a frame (the file's).
  int frame_vertices() const { return frame_vertices_; }

  // Decodes a frame's packed float32 little-endian positions (frame order) into `model_order`
  // (resized to the solved mesh, row per solved vertex). INVALID_ARGUMENT when the byte count is
  // not 12 per frame vertex.
  Status ToModelOrder(const std::string& positions_bytes, Positions* model_order) const;

 private:
  int frame_vertices_ = 0;
  // Per solved vertex: the frame vertex it is read from (the first file vertex that maps to it).
  std::vector<int> source_of_mesh_vertex_;
};

}  // namespace deform::animation
