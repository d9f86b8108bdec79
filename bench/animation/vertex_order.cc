#include "animation/vertex_order.h"

#include <cstdint>
#include <cstring>

namespace deform::animation {

StatusOr<VertexOrder> VertexOrder::Create(const std::vector<int>& file_vertex_to_mesh,
                                          int mesh_vertices) {
  VertexOrder order;
  order.source_of_mesh_vertex_.assign(static_cast<std::size_t>(mesh_vertices), -1);
  if (file_vertex_to_mesh.empty()) {
    order.frame_vertices_ = mesh_vertices;
    for (int v = 0; v < mesh_vertices; ++v) order.source_of_mesh_vertex_[v] = v;
    return order;
  }
  order.frame_vertices_ = static_cast<int>(file_vertex_to_mesh.size());
  for (int f = 0; f < order.frame_vertices_; ++f) {
    const int m = file_vertex_to_mesh[f];
    if (m < -1 || m >= mesh_vertices) {
      return Status::InvalidArgument("file vertex " + std::to_string(f) + " maps to vertex " +
                                     std::to_string(m) + " of a " + std::to_string(mesh_vertices) +
                                     "-vertex mesh");
    }
    if (m >= 0 && order.source_of_mesh_vertex_[m] < 0) order.source_of_mesh_vertex_[m] = f;
  }
  for (int m = 0; m < mesh_vertices; ++m) {
    if (order.source_of_mesh_vertex_[m] < 0) {
      return Status::InvalidArgument("solved vertex " + std::to_string(m) +
                                     " has no vertex in the file's order");
    }
  }
  return order;
}

Status VertexOrder::ToModelOrder(const std::string& positions_bytes, Positions* model_order) const {
  const std::size_t expected = static_cast<std::size_t>(frame_vertices_) * 3 * sizeof(float);
  if (positions_bytes.size() != expected) {
    return Status::InvalidArgument("a frame of " + std::to_string(positions_bytes.size()) +
                                   " position bytes, expected " + std::to_string(expected) +
                                   " (3 float32 per vertex for " + std::to_string(frame_vertices_) +
                                   " vertices)");
  }
  const auto* data = reinterpret_cast<const unsigned char*>(positions_bytes.data());
  const auto mesh_vertices = static_cast<Eigen::Index>(source_of_mesh_vertex_.size());
  model_order->resize(mesh_vertices, 3);
  for (Eigen::Index m = 0; m < mesh_vertices; ++m) {
    const std::size_t first = static_cast<std::size_t>(source_of_mesh_vertex_[m]) * 3;
    for (int c = 0; c < 3; ++c) {
      // Little-endian float32 whatever the host's byte order (as DecodePositions).
      const unsigned char* bytes = data + 4 * (first + static_cast<std::size_t>(c));
      const std::uint32_t bits =
          static_cast<std::uint32_t>(bytes[0]) | static_cast<std::uint32_t>(bytes[1]) << 8 |
          static_cast<std::uint32_t>(bytes[2]) << 16 | static_cast<std::uint32_t>(bytes[3]) << 24;
      float value;
      std::memcpy(&value, &bits, sizeof(float));
      (*model_order)(m, c) = static_cast<double>(value);
    }
  }
  return Status::Ok();
}

}  // namespace deform::animation
